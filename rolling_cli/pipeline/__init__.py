"""One solve, stage by stage: case -> plan -> influence -> contact system -> solver -> result.

* :func:`plan` (pure, no solves): E*, R*, beta, the contact scale a, the contact
  grid and the effects. a is the Hertz half-width when the load is prescribed
  on two half-spaces; otherwise a first guess from closed forms
  (:func:`first_guess`) that the mesh path measures.
* :func:`build_contact_system`: the influence (closed form or BEM) and the
  linear rolling system of a plan.
* :func:`solve`: walks the **mesh path** with the continuation driver
  (:func:`rolling_cli.solver.continuation.follow`): levels that measure a by
  coarse frictionless solves (overlap control, layers), coarse grids for large
  coupled half-plane grids (grid sequencing), the case's own grid, and larger
  zones while the contact reaches the zone's edge, and with
  ``discretization.tolerance`` the adaptive levels (:mod:`rolling_cli.adapt.levels`:
  refined meshes until the error estimate meets the tolerance or a cap). Each
  level starts from the previous level's solution moved onto its grid (an
  explicit transfer), the first from Hertz and Carter
  (:mod:`rolling_cli.solver.initial`). Each level's solve runs the solver
  strategies (:mod:`rolling_cli.solver.strategies`) on its own iteration
  budget, ``solver.max_iterations``.
* :func:`assemble`: the :class:`~rolling_cli.result.Result`.

Sweeps reuse the expensive stages: :func:`prepare` gives the plan and the
contact system of a case (influences are memoised, BEM ones cached on disk,
measured half-widths memoised), and :func:`solve` accepts a prebuilt system and
a warm start.
"""

from __future__ import annotations

import dataclasses
import logging
import time

from ..case import Case, case_to_toml, load_case
from ..errors import ConvergenceError, ZoneError
from ..result import Result
from ..solver import formulation
from ..solver.formulation import State
from ..solver.strategies import Solution
from ..solver.system import ContactSystem
from .assemble import _attach_stresses, assemble  # noqa: F401 (the pipeline's public names)
from .mesh_path import MeshPath, _LevelFailed, _task, _zone_error, estimate_half_width, measured_plan, prepare  # noqa: F401 (the pipeline's public names)
from .planning import (  # noqa: F401 (the pipeline's public names)
    LAYER_ELEMENT_FRACTION,
    Level,
    Plan,
    build_contact_system,
    check_gross_sliding,
    first_guess,
    hertz_applies,
    initial_state,
    plan,
)
from .resources import check_resources

log = logging.getLogger(__name__)


#: mu |beta_Dundurs| above which the coupling is strong, and |beta_Dundurs| / mu above which the
#: friction is tiny against it (both named in failure messages).
STRONG_COUPLING = 0.6


TINY_FRICTION = 1e3


def solve(
    case: Case | str | dict,
    *,
    start: State | None = None,
    system: ContactSystem | None = None,
    keep_failed: bool = False,
    use_cache: bool = True,
    compare_start: bool = False,
) -> Result:
    """Solve a case (a :class:`Case`, a case-file path or a TOML dict); return a :class:`Result`.

    ``start`` is a warm start on the case's own grid (a converged or predicted
    neighbour; with ``compare_start`` it is used only when its residual is below
    the cold start's), ``system`` a prebuilt contact system for this case (sweeps
    reuse it). Raises :class:`ConvergenceError`, :class:`ZoneError` or
    :class:`GrossSlidingError`; with ``keep_failed=True`` a failed solve returns
    its best iterate marked ``converged = False`` instead of raising.
    """
    if not isinstance(case, Case):
        case = load_case(case)
    t0 = time.perf_counter()
    check_gross_sliding(case)
    if system is None:
        check_resources(case)  # refuse what will not fit before allocating anything
    base = measured_plan(case, use_cache) if system is not None else plan(case)
    for warning in base.effects.warnings:
        log.warning(warning)
    path = MeshPath(case, base, system, start, use_cache, compare_start=compare_start)
    try:
        try:
            final = path.run()
        except _LevelFailed as failed:
            return _failure(failed.level, failed.error, path, keep_failed)
        if final.failure is not None:
            return _failure(final, final.failure, path, keep_failed)
    except ConvergenceError:
        if base.effects.tangential and case.friction.law != "constant":
            from .branches import beyond_the_peak

            beyond_the_peak(case, solve, prepare)  # raises when the force is beyond the curve's peak
        raise
    if final.touches_edge:
        raise _zone_error(final)
    result = assemble(final, path.history, path.timings)
    if final.case.discretization.zone != case.discretization.zone:
        result.attributes["zone_note"] = (
            f"discretization.zone enlarged from {case.discretization.zone:g} to {final.case.discretization.zone:g} "
            f"(contact_elements {case.discretization.contact_elements} to "
            f"{final.case.discretization.contact_elements}, the same element length): "
            + (
                "the coupling is strong and moves the contact to one side"
                if final.case.discretization.zone == path.case.discretization.zone
                else "the contact reached the edge of the requested zone"
            )
        )
    if path.adaptation is not None:
        result.attributes.update(path.adaptation.attributes(final.plan.grid))
        if case.bodies.A.finite or case.bodies.B.finite:  # the estimate reads the contact tractions only
            from ..adapt.levels import FINITE_BODY_SCOPE  # (adaptive solves only: kept out of fixed meshes' imports)

            result.attributes["adaptive_method"] += FINITE_BODY_SCOPE
        disc = dataclasses.replace(final.case.discretization, contact_elements=case.discretization.contact_elements)
        result.case_toml = case_to_toml(dataclasses.replace(final.case, discretization=disc))
        if not path.adaptation.met:
            log.warning("%s", path.adaptation.note)
    result.attributes["time_total_solve"] = time.perf_counter() - t0
    result.attributes["start"] = "warm" if path.warm else "cold"
    if path.warm:
        result.attributes["start_traction"] = path.start_traction
    result.attributes["iterations_total"] = int(sum(level.iterations for level in path.levels.values()))
    if case.solver.branch != "auto" and result.converged:
        from .branches import on_branch

        result = on_branch(case, result, solve, prepare)
    return _attach_stresses(final.case, final.plan, result)


def _failure(level: Level, err: ConvergenceError, path: MeshPath, keep_failed: bool) -> Result:
    """A failed level: a ZoneError when its best iterate presses on the zone's ends, else the
    ConvergenceError (naming the level, and strong coupling where it applies); or, with
    ``keep_failed``, the best iterate as a result marked not converged."""
    partial = err.partial
    if partial is not None and (partial.p_n[0] < 0.0 or partial.p_n[-1] < 0.0):
        raise ZoneError(
            "the contact reaches the edge of the potential contact zone during the iteration",
            residual=err.residual,
            iterations=err.iterations,
            cause="discretization.zone is too small for this case; enlarge it",
        ) from err
    cause = err.cause
    beta, mu = abs(0.5 * level.plan.beta_seed), level.case.friction.mu
    if beta * mu > STRONG_COUPLING:
        cause += f"; the normal-tangential coupling is strong (mu |beta_Dundurs| = {beta * mu:.2f})"
    elif mu > 0.0 and beta > TINY_FRICTION * mu:
        cause += (
            f"; friction is tiny against the coupling (|beta_Dundurs| / mu = {beta / mu:.3g}): the adhesion zone is "
            "narrower than a node, so Q(xi) is a staircase; refine the mesh or raise solver.max_iterations"
        )
    where = {
        "a-estimate": " in the frictionless pre-solve that measures the contact half-width",
        "coarse grid": " on a coarse grid",
    }.get(level.kind, "")
    message = str(err).split(", relative residual")[0].replace("did not converge", "did not converge" + where, 1)
    err = ConvergenceError(
        message, residual=err.residual, iterations=err.iterations, history=path.history, cause=cause, partial=partial
    )
    if not keep_failed or partial is None or level.kind not in ("case grid", "enlarged zone"):
        raise err
    task = _task(level.case, level.plan, level.built)
    problem = task.problem(task.full_mode)
    prepared = task.prepared(partial)
    ev = formulation.evaluate(problem, prepared, formulation.traction_scales(problem, prepared))
    ev.stick[:] = False
    level.solution = Solution(prepared, ev, problem)
    result = assemble(level, path.history, path.timings, converged=False)
    result.attributes["message"] = str(err)
    return _attach_stresses(level.case, level.plan, result)


__all__ = [
    "Plan",
    "plan",
    "prepare",
    "solve",
    "assemble",
    "build_contact_system",
    "check_gross_sliding",
    "estimate_half_width",
    "StrategyFailed",
]
