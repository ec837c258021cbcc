"""Choose and build the influence model of a planned case.

* ``half-plane``: the closed form of :mod:`.halfplane` for the pair, with the
  coupling blocks only when the effects call for them.
* ``bem``: one BEM condensation per distinct deformable body (:mod:`.bem`):
  a half-space block of half-width ``block_width`` a and depth ``block_depth``
  a for an elastic body, the layer (thickness b, free length ``layer_length``
  b beyond the zone on each side) for a layered one; none for a rigid body; one
  for two identical bodies. The pair is formed by :func:`~rolling_cli.influence.combine`.

Results are memoised in-process and, for the BEM, cached on disk
(:mod:`.cache`) on everything they depend on, so sweeps and re-runs never
rebuild them.
"""

from __future__ import annotations

import functools
import logging

from . import Compliance, bem, cache, combine, halfplane

log = logging.getLogger(__name__)


def pair_compliance(case, the_plan, use_cache: bool = True) -> tuple[Compliance, dict[str, str]]:
    """The pair compliance on the plan's contact grid [length/stress], and where
    each body's influence came from ("computed", "cache", "reused", "rigid",
    "closed form")."""
    a, b = case.bodies.A, case.bodies.B
    coupling = the_plan.effects.coupling
    if case.discretization.influence == "half-plane":
        pair = _halfplane(the_plan.grid, a.modulus, a.ratio, b.modulus, b.ratio, coupling)
        return pair, {"A": "closed form", "B": "closed form"}
    origin = {}
    bodies = {}
    for label, body in (("A", a), ("B", b)):
        if body.rigid:
            bodies[label], origin[label] = None, "rigid"
        elif label == "B" and the_plan.effects.identical_bodies:
            bodies[label], origin[label] = bodies["A"], "reused"
        else:
            inputs = bem_inputs(case, the_plan, body)
            bodies[label], origin[label] = _bem_body(inputs, use_cache)
    return combine(bodies["A"], bodies["B"], coupling), origin


def bem_inputs(case, the_plan, body) -> dict:
    """Everything a BEM body compliance depends on (the cache key) [length, stress]."""
    disc = case.discretization
    grid = the_plan.grid
    if body.kind == "layered":
        thickness = float(body.layer_thickness)
        geometry = {"half_width": grid.half_width + disc.layer_length * thickness, "depth": thickness}
    else:
        geometry = {
            "half_width": disc.block_width * the_plan.half_width,
            "depth": disc.block_depth * the_plan.half_width,
        }
    return {
        "kind": body.kind,
        "young": float(body.young),
        "poisson": float(body.poisson),
        "zone_half_width": grid.half_width,
        "elements": grid.elements,
        **geometry,
    }


def _bem_body(inputs: dict, use_cache: bool) -> tuple[Compliance, str]:
    frozen = tuple(sorted(inputs.items()))
    if frozen in _memo:
        return _memo[frozen], "reused in-process"
    found, origin = cache.cached(inputs, lambda: _compute_bem(inputs), use_cache)
    _memo[frozen] = found
    if len(_memo) > 8:
        _memo.pop(next(iter(_memo)))
    return found, origin


_memo: dict[tuple, Compliance] = {}


def clear_memo() -> None:
    """Forget the in-process influence memo (benchmarks time cold builds)."""
    _memo.clear()
    _halfplane.cache_clear()


def _compute_bem(inputs: dict) -> Compliance:
    from ..grid import ContactGrid

    grid = ContactGrid(inputs["zone_half_width"], inputs["elements"], 2)
    largest = inputs["depth"] if inputs["kind"] == "layered" else None
    mesh = bem.body_mesh(grid, inputs["half_width"], inputs["depth"], largest=largest)
    log.info("BEM %s: %d elements, %d nodes", inputs["kind"], mesh.elements, mesh.size)
    return bem.condensed(mesh, grid, inputs["young"], inputs["poisson"])


@functools.lru_cache(maxsize=8)
def _halfplane(grid, young_a, poisson_a, young_b, poisson_b, coupling) -> Compliance:
    return halfplane.pair_compliance(grid, young_a, poisson_a, young_b, poisson_b, coupling)
