"""Memory and work of one solve, estimated before anything is allocated.

:func:`check_resources` refuses a case whose estimated peak memory exceeds
what the machine can give this process (:func:`available_memory`), with a
one-line :class:`~rolling_cli.errors.CaseError` naming the key that drives the
size, the estimate and the memory available. :func:`estimate` is a small
explicit model of the arrays each stage holds at its peak, counted in 8-byte
doubles (n contact nodes, N boundary nodes and E elements of a BEM body, n_c
contact nodes in the Newton system, m the size of the reduced Newton matrix):

* **half-plane influence** (:mod:`~rolling_cli.influence.halfplane`):
  S_nn and S_tt (= -S_nn), plus the shared S_nt = S_tn when coupled:
  (2 + coupled) n^2; on the matrix-free path (uniform grids from
  ``halfplane.OPERATOR_NODES`` nodes) each block is a block-Toeplitz
  operator of ~4 m n doubles (m nodes per element: offset blocks and their
  spectrum), and so are B_tt (+ B_tn).
* **BEM body** (:mod:`~rolling_cli.influence.bem`), split into its two
  mirror halves (every body the model meshes is its own mirror image; one
  that is not would need the whole system, twice this), the larger of
  assembly, 2 N^2 + 2 N (n + 1) (each half's system A, N x N, and its
  right-hand sides, N x (n + 1), factorised and solved in place) plus the
  element integrals of one block and their temporaries,
  :data:`BEM_BLOCK_TEMPORARIES` min(12 N E, :data:`BEM_BLOCK`), and
  condensation, 2 N (n + 1) + 4 n^2 (the solutions and the four blocks);
  then 4 n^2 (its four blocks) are kept. A finite cylinder of at most
  ``influence.bem.condense.SMALL_SYSTEM`` unknowns is solved by numpy's LU,
  on copies: 3 N^2 + 4 N (n + 1) while a half is solved, if that is larger.
* **pair and system**: the pair blocks (2 + 2 coupled) n^2 for BEM (the
  half-plane blocks are the pair's already), and B_tt (+ B_tn) n^2; the
  "element" slip derivative adds 2 n^2 of temporaries while it is built.
* **Newton** (:mod:`~rolling_cli.solver.newton`): the reduced matrix m^2, its
  LAPACK copy m^2 and 2 n_c^2 of gathered blocks, with n_c = n / zone (the
  Hertz contact) and m = n_c (decoupled: normal and tangential solves apart)
  or 2 n_c (coupled, every contact node adhering at worst). Matrix-free
  (:func:`_krylov_newton`): the preconditioner's band, the GMRES basis, the
  band assembly's temporaries and O(n) vectors, all linear in n.
* **grid sequencing** (coupled half-plane solves from ``SEQUENCING_ELEMENTS``):
  each coarse level is a level of its own, its influence kept (memoised)
  while the finer ones run; the peak is the largest level's.
* **pre-solve** (an overlap, or a layer): coarse BEM solves measure a before
  the mesh is made (:func:`rolling_cli.pipeline.estimate_half_width`); their
  meshes are counted the same way (the first trial), and a is taken as
  :func:`rolling_cli.pipeline.first_guess`.

Measured peak RSS stays within :data:`ALLOCATOR_MARGIN` of the traced arrays
(allocator and LAPACK workspace; ``tests/test_resources.py``,
``benchmarks/bench_resources.py``). Not counted: a second attempt after the
potential zone is enlarged (the first one's influence stays memoised), the
``--error-estimate`` re-solve (a quarter of the size), sweeps' several
workers (pass ``copies``), and the dense LU a stalled Krylov step falls back to
(at most ``matrix_free.DENSE_FALLBACK`` unknowns: 128 MB and its LU copy).

The work is a rough count of floating-point operations: BEM assembly
(:data:`BEM_PAIR_FLOPS` per collocation node and element), LU
factorisations (2/3 k^3) and :data:`NEWTON_ITERATIONS` Newton iterations.
When a change makes the code allocate differently, update the stage
functions here and the measurement test says whether the model still holds.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from ..errors import CaseError
from ..model import materials
from .machine import available_memory, format_bytes  # noqa: F401 (re-exported: sweeps and the mesh path ask here)

#: Peak RSS over the traced arrays of the model (allocator, LAPACK workspace,
#: small arrays): measured 1.00-1.20 on the test sizes; the estimate includes it.
ALLOCATOR_MARGIN = 1.2

#: Newton iterations assumed by the work estimate (the test cases take 2-15).
NEWTON_ITERATIONS = 10

#: Floating-point operations per BEM collocation node and element (a rough mean: most
#: pairs are collinear, in closed form; the others take 10-point Gauss rules).
BEM_PAIR_FLOPS = 300

#: Doubles of one block of BEM element integrals, H and G (``influence.bem.assembly.BLOCK``).
BEM_BLOCK = 1.0e6

#: A block's integrals with their temporaries (the collinear closed forms, the Gauss rules' chunks of
#: ``influence.bem.assembly._CHUNK`` points, the additions), over the block's size: measured 2.1-2.9
#: from 120 to 800 contact elements, half-space and layer.
BEM_BLOCK_TEMPORARIES = 2.6

#: Element growth of the BEM mesh away from the zone (``influence.bem.mesh.rectangle``).
BEM_GROWTH = 1.4

#: Doubles per unknown while the Krylov preconditioner's band is assembled (the per-position
#: arrays and one diagonal's temporaries of ``solver.near_field._band``). With KRYLOV_VECTORS and
#: KRYLOV_IMPORTS fitted to the traced peaks of 3,000-10,000 nodes (model / traced 0.9-1.2, Carter
#: and the dissimilar case); at 1,200 nodes the fixed import term makes the model up to 1.7x the
#: traced peak (it bounds the resident set, which the imports do grow).
KRYLOV_ASSEMBLY_TEMPORARIES = 20.0

#: Doubles per contact node of the matrix-free Newton's vectors (transforms of the tractions,
#: node states, evaluations, history): measured.
KRYLOV_VECTORS = 100.0

#: The modules the matrix-free path imports when it first runs (scipy.fft, the LAPACK band
#: routines) and their plan caches, in doubles (3 MB): fitted with KRYLOV_VECTORS to the traced
#: peaks (the resident set grew by ~6 MB at 1,200 - 3,000 nodes, where it is most of it; refitted
#: on 2026-11-22 when the band assembly lost its gathered chunks and the traced peaks fell by a third).
KRYLOV_IMPORTS = 3.0e6 / 8

_DOUBLE = 8


@dataclass(frozen=True)
class Estimate:
    """Estimated peak memory [bytes] and work [floating-point operations] of one solve.

    ``stage`` names the stage that sets the peak, ``nodes`` the contact nodes n,
    ``boundary_nodes`` the largest BEM body's N (0 without BEM), ``key`` the
    dotted case key that drives the size.
    """

    bytes: float
    flops: float
    stage: str
    nodes: int
    boundary_nodes: int
    key: str

    def describe(self) -> str:
        """One phrase: the model size behind the estimate."""
        text = f"{_count(self.nodes)} contact nodes"
        if self.boundary_nodes:
            text += f", {_count(self.boundary_nodes)} BEM boundary nodes"
        return f"{text}; peak in {self.stage}"

    def as_dict(self) -> dict:
        """The estimate as ``rollc check`` prints it (bytes, floating-point operations)."""
        available = available_memory()
        out: dict[str, float | str] = {"memory_estimate": float(self.bytes), "work_estimate": float(self.flops)}
        if available is not None:
            out["memory_available"] = available
        out["memory_note"] = self.describe()
        return out


def _count(value: int) -> str:
    return str(value) if value < 1e6 else f"{value:.3g}"


def estimate(case) -> Estimate:
    """Peak memory and rough work of solving ``case`` once (see the module docstring).

    Allocates nothing that grows with the mesh: the BEM meshes are counted,
    not built.
    """
    from .planning import first_guess

    a_body, b_body = case.bodies.A, case.bodies.B
    e_star = materials.effective_modulus(a_body.modulus, a_body.ratio, b_body.modulus, b_body.ratio)
    r_star = materials.effective_radius(a_body.radius, b_body.radius)
    half_width = first_guess(case, e_star, r_star)
    stages: list[tuple[str, float, float, int, int, str]] = []  # name, doubles, flops, n, N, key
    if case.normal.load is None or _layered(case):
        stages.append(_presolve(case, half_width))
    stages.append(_main(case, half_width))
    name, doubles, _, nodes, boundary, key = max(stages, key=lambda s: s[1])
    flops = sum(s[2] for s in stages)
    return Estimate(ALLOCATOR_MARGIN * _DOUBLE * doubles, flops, name, nodes, boundary, key)


def _layered(case) -> bool:
    return case.bodies.A.kind == "layered" or case.bodies.B.kind == "layered"


def _main(case, half_width: float) -> tuple[str, float, float, int, int, str]:
    """The solve on the case's own mesh, a = ``half_width``, after its coarse grid levels
    (grid sequencing), whose influences stay memoised while the finer levels run."""
    from .planning import SEQUENCING_ELEMENTS, plan

    disc = case.discretization
    the_plan = plan(case, half_width=half_width, check=False)
    levels = [(case, the_plan)]
    if (
        the_plan.effects.influence == "half-plane"
        and the_plan.effects.strategy == "coupled"
        and disc.contact_elements >= SEQUENCING_ELEMENTS
    ):
        elements = disc.contact_elements
        while elements >= SEQUENCING_ELEMENTS:
            elements //= 4
            coarse = dataclasses.replace(case, discretization=dataclasses.replace(disc, contact_elements=elements))
            levels.insert(0, (coarse, plan(coarse, half_width=half_width, check=False)))
    memoised, flops, stages = 0.0, 0.0, []
    for level_case, level_plan in levels:
        name, doubles, level_flops, kept, boundary, key = _level(level_case, level_plan)
        coarse = level_plan is not the_plan
        stages.append((name + (" on a coarse grid" if coarse else ""), memoised + doubles))
        memoised += kept
        flops += level_flops
    name, doubles = max(stages, key=lambda s: s[1])
    return name, doubles, flops, the_plan.grid.size, boundary, key


def _level(case, the_plan) -> tuple[str, float, float, float, int, str]:
    """One mesh level: its peak stage and doubles, work, the influence it keeps memoised,
    the largest BEM N and the driving key."""
    disc = case.discretization
    n = the_plan.grid.size
    coupled = the_plan.effects.coupling
    stages, flops, boundary, key = _influence(case, the_plan)
    kept = _kept_influence(case, the_plan)
    strategy_coupled = the_plan.effects.strategy == "coupled"
    if _operators(the_plan):
        system = (1 + coupled) * (_toeplitz_doubles(the_plan.grid) + 2 * n)
        newton, newton_flops = _krylov_newton(n, disc.zone, strategy_coupled)
    else:
        system = (1 + coupled) * n**2
        newton, newton_flops = _newton(n, disc.zone, strategy_coupled)
        if disc.slip_derivative == "element":
            stages.append(("the contact system", kept + system + 2 * n**2))
    stages.append(("Newton", kept + system + newton))
    name, doubles = max(stages, key=lambda s: s[1])
    return name, doubles, flops + newton_flops, kept, boundary, key


def _operators(the_plan) -> bool:
    """True when the level's half-plane blocks are block-Toeplitz operators (the matrix-free path)."""
    if the_plan.effects.influence != "half-plane":
        return False
    from ..influence.halfplane import use_operators

    return use_operators(the_plan.grid)


def _toeplitz_doubles(grid) -> float:
    """Doubles of one block-Toeplitz operator: its 2 N_e - 1 offset blocks of m x m values and
    their spectrum, m^2 complex values per frequency of a transform of length ~2 N_e: 4 m n."""
    m = grid.size // grid.elements
    return 4.0 * m * grid.size


def _influence(case, the_plan) -> tuple[list[tuple[str, float]], float, int, str]:
    """Peak stages of the influence build, its work, the largest BEM N and the driving key."""
    n = the_plan.grid.size
    coupled = the_plan.effects.coupling
    if _operators(the_plan):
        doubles = (2 + coupled) * _toeplitz_doubles(the_plan.grid)
        return [("the half-plane influence", doubles)], 10.0 * doubles, 0, "discretization.contact_elements"
    if the_plan.effects.influence == "half-plane":
        return [("the half-plane influence", (2 + coupled) * n**2)], 10.0 * n**2, 0, "discretization.contact_elements"
    stages = []
    flops = 0.0
    kept = 0.0
    boundary = 0
    key = "discretization.contact_elements"
    for label in _computed_bodies(case, the_plan):
        body = getattr(case.bodies, label)
        big_n, big_e = body_mesh_size(case, the_plan, body)
        block = BEM_BLOCK_TEMPORARIES * min(12.0 * big_n * big_e, BEM_BLOCK)
        assembly = 2.0 * big_n**2 + 2.0 * big_n * (n + 1) + block  # two halves of N unknowns each
        if body.finite and big_n <= _small_system():  # numpy's LU: copies of one half and its solution
            assembly = max(assembly, 3.0 * big_n**2 + 4.0 * big_n * (n + 1))
        condensation = 2.0 * big_n * (n + 1) + 4.0 * n**2
        stages.append((f"the BEM influence of body {label}", kept + max(assembly, condensation)))
        flops += 0.5 * big_n * big_e * BEM_PAIR_FLOPS + (4.0 / 3.0) * big_n**3 + 4.0 * big_n**2 * n
        kept += 4 * n**2
        if big_n > boundary:
            boundary = big_n
            if body.kind == "layered" and big_n - n > n:
                key = f"bodies.{label}.layer_thickness"
    return stages, flops, boundary, key


def _small_system() -> int:
    """Unknowns up to which a finite body's halves are solved by numpy's LU, on copies
    (``influence.bem.condense.SMALL_SYSTEM``)."""
    from ..influence.bem.condense import SMALL_SYSTEM

    return SMALL_SYSTEM


def _computed_bodies(case, the_plan) -> list[str]:
    """The bodies whose BEM influence is computed (not rigid, not a reused twin)."""
    labels = [label for label in ("A", "B") if not getattr(case.bodies, label).rigid]
    if the_plan.effects.identical_bodies and len(labels) == 2:
        labels = ["A"]
    return labels


def _kept_influence(case, the_plan) -> float:
    """Influence arrays held through the solve [doubles]: memoised bodies and the pair."""
    n = the_plan.grid.size
    coupled = the_plan.effects.coupling
    if _operators(the_plan):
        return (2 + coupled) * _toeplitz_doubles(the_plan.grid)
    if the_plan.effects.influence == "half-plane":
        return (2 + coupled) * n**2
    bodies = len(_computed_bodies(case, the_plan))
    return 4 * bodies * n**2 + (2 + 2 * coupled) * n**2


def _newton(n: int, zone: float, coupled: bool) -> tuple[float, float]:
    """Peak doubles and work of the Newton iterations on n nodes."""
    contact = n / zone
    size = 2 * contact if coupled else contact
    doubles = 2 * size**2 + 2 * contact**2
    flops = NEWTON_ITERATIONS * ((2.0 / 3.0) * size**3 + 8.0 * n**2)
    return doubles, flops


def _krylov_newton(n: int, zone: float, coupled: bool) -> tuple[float, float]:
    """Peak doubles and work of the matrix-free Newton iterations on n nodes
    (:mod:`rolling_cli.solver.matrix_free`): :data:`KRYLOV_VECTORS` per node of vectors
    (transforms, node states, evaluations), the modules the path imports on first use
    (:data:`KRYLOV_IMPORTS`) and the largest of three phases of each step, with
    B = (3 h + 1) per unknown the preconditioner's band in LAPACK storage (h = (W + 1) per
    node - 1, W = NEAR_FIELD, per node 2 coupled): its assembly (B and the assembly's
    temporaries, per unknown), its single-precision factorisation (1.5 B: the double band and its float32
    copy) and GMRES (B / 2, the Arnoldi basis and the preconditioned directions, 2 restart + 1
    per unknown), and the coarse-grid correction (:mod:`rolling_cli.solver.coarse`,
    C coarse unknowns, at least one per :data:`~rolling_cli.solver.coarse.AGGREGATE` unknowns):
    its assembly (B / 2 and 4 C^2: the corner sums, their difference, the gathered block and the
    coarse matrix) and its LU during GMRES (C^2)."""
    from ..solver import coarse, krylov, matrix_free

    contact = n / zone
    per_node = 2 if coupled else 1
    size = per_node * contact
    half = per_node * (matrix_free.NEAR_FIELD + 1) - 1
    band = (3 * half + 1) * size
    restart = krylov.RESTART
    chunk = KRYLOV_ASSEMBLY_TEMPORARIES * size
    fine = int(math.ceil(size))
    unknowns = math.ceil(fine / coarse.aggregate_nodes(fine, 1)) + 2 if matrix_free.TWO_LEVEL else 0
    phases = (
        band + chunk,
        1.5 * band,
        0.5 * band + 4.0 * unknowns**2,
        0.5 * band + (2 * restart + 1) * size + unknowns**2,
    )
    doubles = max(phases) + KRYLOV_VECTORS * n + KRYLOV_IMPORTS
    iterations = 50  # Krylov iterations per Newton step, a rough mean (benchmarks/bench_solve.py)
    per_iteration = 40.0 * n * math.log2(max(n, 2)) + 4.0 * size * (3 * half + 1) + 4.0 * restart * size
    if unknowns:  # one more product per iteration; the coarse matrix and its LU per step
        per_iteration += 40.0 * n * math.log2(max(n, 2)) + 2.0 * unknowns**2
    coarse_step = 2.0 / 3.0 * unknowns**3 + 30.0 * unknowns**2
    flops = NEWTON_ITERATIONS * (2.0 * size * half**2 + coarse_step + iterations * per_iteration)
    return doubles, flops


def _presolve(case, guess: float) -> tuple[str, float, float, int, int, str]:
    """The first coarse frictionless pre-solve that measures a (BEM, zone PRESOLVE_ZONE guesses)."""
    from .planning import PRESOLVE_ZONE, presolve_case

    trial = presolve_case(case, guess, PRESOLVE_ZONE)
    _, doubles, flops, n, boundary, key = _main(trial, guess)
    if key == "discretization.contact_elements" and not _layered(case):
        key = "normal.overlap"
    return "the pre-solve that measures a", doubles, flops, n, boundary, key


def body_mesh_size(case, the_plan, body) -> tuple[int, int]:
    """Boundary nodes N and elements E of a body's BEM mesh, counted without building it.

    The geometry is :func:`rolling_cli.influence.build.bem_inputs`'; the counts
    follow :func:`rolling_cli.influence.bem.mesh.rectangle` (tested against it).
    """
    from ..influence.build import bem_inputs

    inputs = bem_inputs(case, the_plan, body)
    if inputs.get("shape") == "cylinder":  # the annulus (its mesh counted from its edges alone)
        from ..influence.bem.cylinder import annulus_size

        nodes, elements = annulus_size(
            inputs["zone_half_width"], inputs["elements"], inputs["radius"], inputs["inner_radius"]
        )
        if "core_young" in inputs:  # an elastic core: its own whole system, the interface and its bore
            from ..influence.bem.core import BORE_ELEMENTS

            core, bore = float(inputs["inner_radius"]), float(inputs["core_bore"])
            count = max(BORE_ELEMENTS, int(math.ceil(2.0 * math.pi * bore / (core - bore))))
            # (the core is solved whole: the model, built for mirror halves, reads it low)
            nodes, elements = nodes + 2 * count + 1, elements + count
        return nodes, elements
    largest = inputs["depth"] if inputs["kind"] == "layered" else None
    return rectangle_size(inputs["zone_half_width"], inputs["elements"], inputs["half_width"], inputs["depth"], largest)


def rectangle_size(
    zone_half_width: float, elements: int, half_width: float, depth: float, largest: float | None = None
) -> tuple[int, int]:
    """Nodes and elements of ``rectangle(half_width, depth, zone edges, largest=largest)`` [-]."""
    h = 2.0 * zone_half_width / elements
    big = largest if largest is not None else min(depth, half_width) / 4.0
    bottom, _ = graded_count(half_width, min(big, max(h, depth / 8.0)), BEM_GROWTH, big)
    top, corner = graded_count(half_width - zone_half_width, h, BEM_GROWTH, big)
    side, _ = graded_count(depth, corner, BEM_GROWTH, big)
    segments = (2 * bottom, side, top, top, side)  # bottom, right side, top right, top left, left side
    nodes = sum(2 * k + 1 for k in segments) + 3 * elements
    return int(nodes), int(sum(segments) + elements)


def graded_count(length: float, first: float, growth: float, largest: float) -> tuple[int, float]:
    """Edges of :func:`rolling_cli.influence.bem.mesh.graded_edges` over ``length``, and
    its last edge length, in closed form (sizes first * growth^k capped at ``largest``)."""
    target = length * (1.0 - 1e-9)
    first = min(first, largest)
    if not target > 0.0:  # nothing to mesh (a layer thinner than the rounding of the zone's width)
        return 0, first
    growing = 0 if first >= largest else math.ceil(math.log(largest / first) / math.log(growth))
    grown = first * (growth**growing - 1.0) / (growth - 1.0)  # the growing sizes' sum
    if grown >= target:
        count = max(1, math.ceil(math.log1p(target * (growth - 1.0) / first) / math.log(growth)))
        total = first * (growth**count - 1.0) / (growth - 1.0)
        last = first * growth ** (count - 1)
    else:
        count = growing + math.ceil((target - grown) / largest)
        total = grown + (count - growing) * largest
        last = largest
    if count > 1 and total - length > 0.5 * last:
        total -= last
        count -= 1
        last = first * growth ** (count - 1) if count <= growing else largest
    return count, last * length / total


def _largest_fitting(case, budget: float) -> int:
    """The most contact elements whose estimate fits ``budget`` [bytes] (0 if none)."""
    disc = case.discretization

    def fits(count: int) -> bool:
        trial = dataclasses.replace(case, discretization=dataclasses.replace(disc, contact_elements=count))
        return estimate(trial).bytes <= budget

    low, high = 2, disc.contact_elements
    if not fits(low):
        return 0
    while high - low > 1:
        mid = (low + high) // 2
        low, high = (mid, high) if fits(mid) else (low, mid)
    return low


def check_resources(case, copies: int = 1) -> Estimate:
    """Refuse ``case`` before any allocation when ``copies`` solves of it at once
    (sweep workers) would not fit in :func:`available_memory`, or when its layer
    would certainly fail the element rule after the costly pre-solve
    (:func:`check_layer_elements`); return the estimate.

    Raises :class:`CaseError` (exit code 2) naming the driving key, the
    estimate and the available memory.
    """
    found = estimate(case)
    available = available_memory()
    if available is None or found.bytes * copies <= available:
        check_layer_elements(case)
        return found
    value = _dotted(case, found.key)
    need = f"{format_bytes(found.bytes)} of memory"
    if copies > 1:
        need += f", {format_bytes(found.bytes * copies)} for {copies} workers"
    if found.key == "discretization.contact_elements":
        fitting = _largest_fitting(case, available / copies)
        allowed = f"at most {fitting} contact elements on this machine" if fitting else "a smaller case"
    elif found.key.endswith("layer_thickness"):
        allowed = "a thicker layer, or a shorter discretization.layer_length or zone"
    else:
        allowed = "a smaller overlap, or fewer contact elements"
    raise CaseError(
        f"{found.key} = {value:g}: the solve needs about {need} ({found.describe()}), "
        f"more than the {format_bytes(available)} available; allowed: {allowed}",
        file=case.source,
        key=found.key,
    )


#: The pre-flight layer check allows a contact this much narrower than the first guess
#: (the guess is within 0.8-1.2 of the measured a for b/a = 0.02-0.5, nu = 0.3-0.5).
GUESS_MARGIN = 2.0


def check_layer_elements(case) -> None:
    """Refuse a layered case whose contact elements would exceed half the layer
    thickness even if the contact were :data:`GUESS_MARGIN` times narrower than its
    first guess: :func:`rolling_cli.pipeline.plan` would refuse it anyway, but only
    after the pre-solve that measures a (issue #15: 100 s and 6 GB for b = 1e-6)."""
    from .planning import LAYER_ELEMENT_FRACTION, first_guess

    layers = [(label, getattr(case.bodies, label)) for label in ("A", "B")]
    layers = [(label, body) for label, body in layers if body.kind == "layered"]
    if not layers:
        return
    a_body, b_body = case.bodies.A, case.bodies.B
    e_star = materials.effective_modulus(a_body.modulus, a_body.ratio, b_body.modulus, b_body.ratio)
    r_star = materials.effective_radius(a_body.radius, b_body.radius)
    smallest = first_guess(case, e_star, r_star) / GUESS_MARGIN
    disc = case.discretization
    for label, body in layers:
        limit = LAYER_ELEMENT_FRACTION * float(body.layer_thickness)
        needed = math.ceil(2.0 * disc.zone * smallest / limit)
        if disc.contact_elements < needed:
            raise CaseError(
                f"discretization.contact_elements = {disc.contact_elements}: too few for the layer of "
                f"bodies.{label} (b = {float(body.layer_thickness):g}): elements must be at most b/2 long, and the "
                f"contact half-width is about {GUESS_MARGIN * smallest:.3g} (thin-layer estimate); allowed: >= "
                f"{needed} elements (at least; a is estimated), or a thicker layer",
                file=case.source,
                key="discretization.contact_elements",
            )


def _dotted(case, key: str) -> float:
    node = case
    for part in key.split("."):
        node = getattr(node, part)
    return node
