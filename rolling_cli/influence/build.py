"""Choose and build the influence model of a planned case.

* ``half-plane``: the closed form of :mod:`.halfplane` for the pair, with the
  coupling blocks only when the effects call for them; with a viscoelastic body
  the steady-rolling kernels of :mod:`.viscoelastic` (speed and direction
  enter).
* ``bem``: one BEM condensation per distinct deformable body (:mod:`.bem`):
  a half-space truncated at half-width ``block_width`` a and depth
  ``block_depth`` a (far-field displacement on the truncation, the approach
  measured from depth D) for an elastic body, the layer (thickness b, free
  length ``layer_length`` b beyond the zone on each side) for a layered one,
  with the steady-rolling history terms of :mod:`.viscoelastic_layer` when the
  layer is viscoelastic (built with E = E_g, then weighted by J), or of
  :mod:`.viscoelastic_cylinder` (periodic round the annulus) for a viscoelastic
  finite cylinder or finite covered roller;
  none for a rigid body; one for two identical bodies. The pair is formed by
  :func:`~rolling_cli.influence.combine`.

The model is the plan's resolved one (``the_plan.effects.influence``, see
:mod:`.choice`). :func:`boundary_solution` gives a BEM body's full boundary
solution for given contact tractions (for interior stresses).

Results are memoised in-process and, for the BEM, cached on disk
(:mod:`.cache`) on everything they depend on, so sweeps and re-runs never
rebuild them.
"""

from __future__ import annotations

import functools
import logging
from typing import TYPE_CHECKING

import numpy as np

from ..model.grid import ContactGrid
from ..model.viscoelastic import bodies as viscoelastic_bodies
from ..model.viscoelastic import from_body, material, viscoelastic_layer
from . import Compliance, combine, halfplane

if TYPE_CHECKING:  # the BEM package (and scipy.linalg) is imported only when a BEM body is built
    from . import bem

log = logging.getLogger(__name__)


def pair_compliance(
    case, the_plan, use_cache: bool = True, normal_only: bool = False
) -> tuple[Compliance, dict[str, str]]:
    """The pair compliance on the plan's contact grid [length/stress], and where
    each body's influence came from ("computed", "cache", "reused", "rigid",
    "closed form"). ``normal_only``: a viscoelastic layer's history on S_nn alone (a frictionless
    normal solve, the a-estimate levels, never reads the other blocks)."""
    a, b = case.bodies.A, case.bodies.B
    coupling = the_plan.effects.coupling
    if the_plan.effects.influence == "half-plane":
        materials = (material(a), material(b))
        if viscoelastic_bodies(case):
            speed = float(case.rolling.speed)
            pair = _viscoelastic(the_plan.grid, *materials, speed, case.rolling.direction, coupling)
        else:
            pair = _halfplane(the_plan.grid, *materials, coupling)
        return pair, {"A": "closed form", "B": "closed form"}
    origin = {}
    bodies: dict[str, Compliance | None] = {}
    for label, body in (("A", a), ("B", b)):
        if body.rigid:
            bodies[label], origin[label] = None, "rigid"
        elif label == "B" and the_plan.effects.identical_bodies:
            bodies[label], origin[label] = bodies["A"], "reused"
        else:
            bodies[label], origin[label] = deformable_body(case, the_plan, body, use_cache, normal_only)
    if a.finite or b.finite:  # exact geometry and hoop strain of finite cylinders
        from . import finite as _finite

        finite_pair = _finite.finite_pair

        pair = finite_pair(bodies["A"], bodies["B"], a.radius, b.radius, a.finite, b.finite, coupling)
        return pair, origin
    return combine(bodies["A"], bodies["B"], coupling), origin


def deformable_body(case, the_plan, body, use_cache: bool = True, normal_only: bool = False) -> tuple[Compliance, str]:
    """One deformable body's own compliance on the plan's grid [length/stress] (BEM, with the
    viscoelastic history terms of a finite cylinder or a cover; ``normal_only``: a cover's history
    on S_nn alone) and where it came from."""
    inputs = bem_inputs(case, the_plan, body)
    found, origin = _bem_body(inputs, use_cache)
    if body.finite and from_body(body) is not None:  # periodic history round the annulus
        key = (tuple(sorted(inputs.items())), body, float(case.rolling.speed), case.rolling.direction)
        if key not in _cylinder_memo:  # kept: the result's power balance reads it again
            _cylinder_memo[key] = _viscoelastic_cylinder(
                found, the_plan.grid, body, float(case.rolling.speed), case.rolling.direction
            )
            if len(_cylinder_memo) > 2:
                _cylinder_memo.pop(next(iter(_cylinder_memo)))
        found = _cylinder_memo[key]
    elif viscoelastic_layer(body):  # the rubber cover: the BEM layer (E_g) with its history terms
        layer_key = (
            tuple(sorted(inputs.items())),
            body,
            float(case.rolling.speed),
            case.rolling.direction,
            normal_only,
        )
        if layer_key not in _layer_memo:  # kept: the result's surface displacements read it again
            _layer_memo[layer_key] = _viscoelastic_layer(
                found, the_plan.grid, body, float(case.rolling.speed), case.rolling.direction, normal_only
            )
            if len(_layer_memo) > 2:
                _layer_memo.pop(next(iter(_layer_memo)))
        found = _layer_memo[layer_key]
    return found, origin


def bem_inputs(case, the_plan, body) -> dict:
    """Everything a BEM body compliance depends on (the cache key) [length, stress]."""
    disc = case.discretization
    grid = the_plan.grid
    if body.finite:  # the whole annulus: outer radius and the rigid shaft's or core's radius
        shape = body.body_shape
        geometry = {
            "shape": shape.name,
            "radius": shape.radius,
            "inner_radius": shape.inner_radius,
            "mesh_rules": cylinder_mesh_rules(),
        }
        if body.elastic_core:  # the cover on an elastic core (:mod:`.bem.core`); absent: keys as before
            geometry.update(core_young=float(body.core_young), core_poisson=float(body.core_poisson))
            geometry["core_bore"] = body.core_bore
    elif body.kind == "layered":
        thickness = float(body.layer_thickness)
        geometry = {"half_width": grid.half_width + disc.layer_length * thickness, "depth": thickness}
    else:
        geometry = {
            "half_width": disc.block_width * the_plan.half_width,
            "depth": disc.block_depth * the_plan.half_width,
        }
    layer = material(body)  # a layered body's: its layer's; a viscoelastic layer's BEM is at E_g
    assert layer is not None, "a rigid body has no BEM"
    inputs = {
        "kind": body.kind,
        "young": layer.young,
        "poisson": layer.poisson,
        "zone_half_width": grid.half_width,
        "elements": grid.elements,
        **geometry,
    }
    if not grid.uniform:  # a graded grid (adaptive levels): keyed on its edges; uniform keys unchanged
        inputs["element_edges"] = tuple(float(e) for e in grid.edges)
    return inputs


def cylinder_mesh_rules() -> int:
    """The version of the finite cylinder's meshing rules (part of its cache key)."""
    from .bem.cylinder import MESH_RULES

    return MESH_RULES


def contact_grid(inputs: dict) -> ContactGrid:
    """The contact grid of BEM ``inputs`` (:func:`bem_inputs`): uniform, or graded on its ``element_edges``."""
    if "element_edges" in inputs:
        return ContactGrid.graded(inputs["element_edges"], 2)
    return ContactGrid(inputs["zone_half_width"], inputs["elements"], 2)


def _bem_body(inputs: dict, use_cache: bool) -> tuple[Compliance, str]:
    """A BEM body's compliance: from the in-process memo, the disk cache or computed. A graded
    grid's (an adaptive level, keyed on its edges) is kept for the last two bodies only (not every
    level's dense matrices: the final level's, which the result's surface displacements read, and
    which serves calls that do not use the disk cache) and uses the disk cache (a re-run meets the
    same levels)."""
    from . import cache  # the disk cache only for BEM bodies (start-up)

    frozen = tuple(sorted(inputs.items()))
    if "element_edges" in inputs:  # the last two graded bodies kept: the result's surfaces read them again
        if not use_cache and frozen in _graded_memo:  # with the disk cache, its entry (verified) as before
            return _graded_memo[frozen], "reused in-process"
        found, origin = cache.cached(inputs, lambda: _compute_bem(inputs), use_cache)
        _graded_memo[frozen] = found
        if len(_graded_memo) > 2:
            _graded_memo.pop(next(iter(_graded_memo)))
        return found, origin
    if frozen in _memo:
        return _memo[frozen], "reused in-process"
    found, origin = cache.cached(inputs, lambda: _compute_bem(inputs), use_cache)
    _memo[frozen] = found
    if len(_memo) > 8:
        _memo.pop(next(iter(_memo)))
    return found, origin


_memo: dict[tuple, Compliance] = {}
#: The last two graded BEM bodies (an adaptive level's; :mod:`.surface` reads the final one again).
_graded_memo: dict[tuple, Compliance] = {}
#: The last viscoelastic finite cylinders' compliances (body, grid and speed in the key).
_cylinder_memo: dict[tuple, Compliance] = {}
#: The last viscoelastic layers' compliances (as :data:`_cylinder_memo`, and whether normal-only).
_layer_memo: dict[tuple, Compliance] = {}


def clear_memo() -> None:
    """Forget the in-process influence memo (benchmarks time cold builds)."""
    _memo.clear()
    _graded_memo.clear()
    _cylinder_memo.clear()
    _layer_memo.clear()
    _halfplane.cache_clear()
    _viscoelastic.cache_clear()
    from . import viscoelastic

    viscoelastic.clear_memo()
    _prepared.cache_clear()
    _prepared_annulus.cache_clear()


def _mesh(inputs: dict) -> tuple[bem.BoundaryMesh, ContactGrid]:
    from . import bem

    grid = contact_grid(inputs)
    layer = inputs["kind"] == "layered"
    largest = inputs["depth"] if layer else None
    mesh = bem.body_mesh(grid, inputs["half_width"], inputs["depth"], largest=largest, far_field=not layer)
    log.info("BEM %s: %d elements, %d nodes", inputs["kind"], mesh.elements, mesh.size)
    return mesh, grid


def _compute_bem(inputs: dict) -> Compliance:
    from .. import blas
    from . import bem

    blas.settle()  # the BEM's LAPACK on the command's threads (scipy's, loaded later, settles in .bem.condense)

    if inputs.get("shape") == "cylinder":
        from .bem import cylinder

        grid = contact_grid(inputs)
        if "core_young" in inputs:  # the cover on an elastic core
            from .bem import core

            return core.condensed(
                grid,
                inputs["radius"],
                inputs["inner_radius"],
                inputs["core_bore"],
                inputs["young"],
                inputs["poisson"],
                inputs["core_young"],
                inputs["core_poisson"],
            )
        return cylinder.condensed(grid, inputs["radius"], inputs["inner_radius"], inputs["young"], inputs["poisson"])
    mesh, grid = _mesh(inputs)
    return bem.condensed(mesh, grid, inputs["young"], inputs["poisson"])


@functools.lru_cache(maxsize=2)
def _prepared(frozen: tuple) -> bem.Condensed:
    from . import bem

    inputs = dict(frozen)
    mesh, grid = _mesh(inputs)
    return bem.prepare_body(mesh, grid, inputs["young"], inputs["poisson"])


def boundary_solution(case, the_plan, label: str, p_n: np.ndarray, p_t: np.ndarray) -> tuple:
    """Full boundary solution of BEM body ``label`` ("A" or "B") for the pair's contact tractions.

    ``p_n``, ``p_t`` (n_c,) [stress] are the pair's nodal tractions on the
    plan's contact grid (a :class:`~rolling_cli.result.Result`'s ``p_n`` and
    ``p_t``; p_t is the traction on A, so body B, in its mirrored frame,
    carries -p_t). Returns ``(mesh, u, t)`` of
    :func:`rolling_cli.influence.bem.boundary_solution`, in the body's own
    block frame (x along the surface, y up, the body below y = 0): nodes
    ``mesh.nodes`` (N, 2) [length], displacements u (N, 2) [length] and
    tractions t (N, 2) [stress] on every boundary node, far-field conditions
    included. The factorised body is memoised (the last two bodies). Raises
    ValueError for a rigid body or a half-plane case (no boundary mesh). A finite
    cylinder's is its annulus (:mod:`.bem.annulus_solution`: the frame of
    :mod:`.bem.cylinder`, centre at (0, -R), the contact nodes' tractions along
    their arc), its p_n and p_t along each node's own normal and tangent.

    For a result ``r`` of ``case``: ``the_plan = pipeline.plan(case,
    half_width=r.mesh_half_width)``.
    """
    body = getattr(case.bodies, label)
    if the_plan.effects.influence != "bem" or body.rigid:
        raise ValueError(f"body {label} has no BEM mesh (rigid body or half-plane model)")
    from . import bem

    inputs = bem_inputs(case, the_plan, body)
    sign = 1.0 if label == "A" else -1.0
    if body.elastic_core:  # the cover on its elastic core: the cover's boundary, its interface held by the core
        from .bem import core

        moduli = (inputs["young"], inputs["poisson"], inputs["core_young"], inputs["core_poisson"])
        geometry = (inputs["radius"], inputs["inner_radius"], inputs["core_bore"])
        return core.boundary_solution(contact_grid(inputs), *geometry, moduli, p_n, sign * np.asarray(p_t))
    if body.finite:  # the annulus, its tractions along its arc (the nodes' own directions)
        from .bem.annulus_solution import annulus_solution

        prepared = _prepared_annulus(tuple(sorted(inputs.items())))
        return annulus_solution(prepared, inputs["radius"], p_n, sign * np.asarray(p_t))
    return bem.boundary_solution(_prepared(tuple(sorted(inputs.items()))), p_n, sign * np.asarray(p_t))


@functools.lru_cache(maxsize=2)
def _prepared_annulus(frozen: tuple) -> bem.Condensed:
    from .bem.annulus_solution import prepare_annulus

    inputs = dict(frozen)
    grid = contact_grid(inputs)
    return prepare_annulus(grid, inputs["radius"], inputs["inner_radius"], inputs["young"], inputs["poisson"])


@functools.lru_cache(maxsize=8)
def _halfplane(grid, material_a, material_b, coupling) -> Compliance:
    return halfplane.materials_pair(grid, material_a, material_b, coupling)


def _viscoelastic_layer(
    elastic: Compliance, grid: ContactGrid, body, speed: float, direction: int, normal_only: bool = False
) -> Compliance:
    """A viscoelastic layer's compliance from its elastic BEM layer (built with E = E_g)."""
    from . import viscoelastic_layer as layer

    model = from_body(body)
    if model is None:
        raise ValueError("not a viscoelastic body")
    return layer.body_compliance(elastic, grid, model, float(body.layer_thickness), speed, direction, normal_only)


def _viscoelastic_cylinder(elastic: Compliance, grid: ContactGrid, body, speed: float, direction: int) -> Compliance:
    """A viscoelastic finite cylinder's compliance from its elastic BEM annulus (built with E = E_g)."""
    from . import viscoelastic_cylinder

    model = from_body(body)
    if model is None:
        raise ValueError("not a viscoelastic body")
    shape = body.body_shape
    return viscoelastic_cylinder.body_compliance(
        elastic, grid, model, shape.radius, shape.inner_radius, speed, direction
    )


@functools.lru_cache(maxsize=8)
def _viscoelastic(grid, material_a, material_b, speed, direction, coupling) -> Compliance:
    from . import viscoelastic

    return viscoelastic.pair_compliance(grid, [material_a, material_b], speed, direction, coupling)
