"""Building a creep-force table by adaptive sampling (``rollc table``; issue 24 item 2).

The axis is the creepage normalised as u = xi R*/(mu a) (a the case's contact
scale: the Hertz half-width of its load on two half-spaces, else the measured
one; Carter's full slip starts at |u| = 1). Each node is one creepage-controlled
solve on the case's own contact system (warm-started from the nearest solved
node), giving Q/(mu P) and, from the sensitivity dQ/dxi
(:mod:`rolling_cli.solver.sensitivity`), its slope d(Q/(mu P))/du =
(dQ/dxi) (mu a/R*) / (mu P): the data of a cubic Hermite interpolant.

Sampling: ``initial`` equally spaced nodes over [lo, hi] (an odd count puts a
node at u = 0, where Carter's law has its second-derivative jump); then every
interval not yet accepted is tested at its midpoint m by one more solve: its
miss is the largest of |f(m) - H(m)| (H the interval's cubic Hermite) and, at
its quarter points, |H_fine - H| (H_fine the Hermite that adds m's value and
slope: a slope at m that disagrees with H's reveals a feature the value alone
can hide), and its estimate is :data:`MARGIN` times the miss. An interval whose
estimate is above the tolerance is split at m (a node) and its halves are
tested in turn; one whose estimate is within it is accepted as it is: the test
point is not made a node. (It once was, the halves inheriting the whole's
estimate, which a kink of the curve defeats: on the aluminium/steel pair near
free rolling, where slip zones appear, the whole [-0.75, -0.5] met 5e-4 at its
midpoint by cancellation and its half [-0.75, -0.625] then missed by 1.5e-3 at
u = -0.70; and at mu = 0.1023 the value at the midpoint of [-1, -0.5] alone
was met to 1.1e-4 while u = -0.94 missed by 4.6e-3, which the slope's quarter-
point test sees: 6e-4.) For a smooth piece the midpoint is where a cubic
Hermite's error peaks (t^2 (1 - t)^2 h^4 f^(4)/4!) and its slope error is nil;
where kinks of the discrete curve move the peak the margin covers it. The
estimate is that of every final interval itself (measured, not a bound). The
loop stops at ``max_cases`` solves, and does not split an interval narrower
than :data:`NARROWEST` of the range (a jump of the discrete curve); either way
the table is written with the estimate it reached, and says it did not meet
the tolerance.

A second axis, the coefficient of friction (``--mu LO:HI``,
:func:`build_friction`): rows of the sampling above (each to
:data:`ROW_SHARE` of the tolerance) at friction nodes, with the slope of
Q/(mu P) in mu at fixed u from the sensitivities, (dQ/dmu + (xi/mu) dQ/dxi)/(mu
P) - Q/(mu^2 P) (xi = u mu a/R* moves with mu); between two rows a cubic
Hermite in mu (the rows' slopes in mu interpolated linearly in u). Each
interval in mu is tested by a whole mid-row, the same way at every node of the
three rows and between them (its miss: the mid-row against the interpolant, and
at the quarter rows the interpolants through the mid-row against it): split
(the mid-row kept) while :data:`MARGIN_MU` times the miss is above the rest of the
tolerance, else accepted with that estimate (the mid-row only tested, as in u).
Carter's law depends on u alone (the decoupled problem is homogeneous in mu and
xi): its slopes in mu vanish and the first rows pass. The rows of one pass (the
first ones, then the mid-rows of every open interval) are independent: they are
solved together, in worker processes with ``--workers`` and journalled for
``--resume`` (:mod:`rolling_cli.study.table_rows`).

The P held is the case's load: a table needs ``normal.load`` (under overlap
control Q/(mu P) would mix the creepage with the load it changes).
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import logging
import time

import numpy as np

from .. import pipeline
from .._version import __version__
from ..case import Case, case_to_toml
from ..errors import CaseError
from ..result import recorded, utc_timestamp
from ..solver.formulation import State
from ..table import FrictionTable, Table, TableRow, between, hermite
from . import table_rows
from .table_rows import Row

log = logging.getLogger(__name__)

#: Default nodes of the first pass and largest number of solves.
INITIAL = 5
MAX_CASES = 200
#: The estimate of an interval in u is this multiple of its miss: a cubic Hermite's error peaks at the
#: midpoint only on a smooth piece; the discrete curve's kinks (zone changes) move the peak (measured:
#: the largest error of 15 to 33 points per interval 1.32 to 1.43 times the miss on Carter at 60
#: elements, up to 2.17 times on the aluminium/steel pair at tolerance 1e-3, interval [-1, -0.875]).
MARGIN = 3.0
#: The same in mu (the miss is the largest over every node of three rows and between them): 2 (the
#: aluminium/steel creepage x mu table at 1e-3: estimate 9.8e-4, largest error of 200 random direct
#: solves 4.2e-4).
MARGIN_MU = 2.0
#: The share of a two-axis table's tolerance given to its rows in u (the rest to the interpolation in
#: mu): a row's cost grows slowly as its tolerance falls (like tol^-1/4 on smooth pieces, tol^-1/2 at
#: kinks), the rows in mu like 1/tol (the kinks in mu make the cubic Hermite first order there).
ROW_SHARE = 1.0 / 3.0
#: Intervals narrower than this fraction of the range are not split: the discrete curve jumps there
#: (an active-set change with two solutions side by side: measured on the aluminium/steel friction
#: table, which bisected such intervals down to 3e-16 until its budget ran out). They are kept with
#: the jump as their estimate, and the table says it did not meet the tolerance.
NARROWEST = 1e-6


def check_request(case: Case, lo: float, hi: float, tolerance: float, source: str | None = None) -> None:
    """Refuse a table that cannot be built, with one line (CaseError): a tolerance <= 0, an empty or
    reversed range, a range beyond the creepage a case may hold, overlap control, no friction."""
    if not tolerance > 0.0:
        raise CaseError(f"--tolerance = {tolerance!r}: allowed: > 0 (an error in Q/(mu P))", file=source)
    if not lo < hi:
        raise CaseError(f"--range = {lo!r}:{hi!r}: allowed: LO:HI with LO < HI (xi R*/(mu a))", file=source)
    if case.normal.load is None:
        raise CaseError(
            "normal.overlap: a table holds the load P; allowed: normal.load (the overlap changes P with xi)",
            file=source,
            key="normal.overlap",
        )
    if not case.friction.mu > 0.0:
        raise CaseError("friction.mu = 0: allowed: mu > 0 (Q/(mu P) needs friction)", file=source, key="friction.mu")
    if case.friction.law != "constant":
        raise CaseError(
            f"friction.law = {case.friction.law!r}: tables of a slip-speed law are not built yet (tried: the shipped "
            'falling law ran out of its solve budget at 1e-3); allowed: law = "constant"',
            file=source,
            key="friction.law",
        )


def _row(
    case: Case, system, the_plan, mu: float, lo: float, hi: float, tolerance: float, initial: int, budget: int, cache
) -> Row:
    """The adaptive sampling of one row (module docstring) at friction ``mu``, at most ``budget`` solves."""
    scale = mu * the_plan.half_width / the_plan.radius  # xi of u = 1
    solved: dict[float, tuple[float, float, float, State]] = {}
    tested: dict[float, tuple[float, float, float, State]] = {}  # test points (warm starts only)
    friction = dataclasses.replace(case.friction, mu=mu)

    def solve_at(u: float) -> None:
        known = {**tested, **solved}
        near = min(known, key=lambda v: abs(v - u)) if known else None
        start = known[near][3] if near is not None else None
        tangential = type(case.tangential)(creep=float(u * scale))
        point = dataclasses.replace(case, friction=friction, tangential=tangential)
        result = pipeline.solve(point, system=system, start=start, use_cache=cache)
        load, ratio = recorded(result.normal_load, "normal_load"), recorded(result.q_over_mu_p, "q_over_mu_p")
        dq_dxi, dq_dmu = recorded(result.dQ_dxi, "dQ_dxi"), recorded(result.dQ_dmu, "dQ_dmu")
        overlap, creep = recorded(result.solved_overlap, "solved_overlap"), recorded(result.creep, "creep")
        slope = dq_dxi * scale / (mu * load)
        # d(Q/(mu P))/dmu at fixed u: xi = u mu a/R* moves with mu, dxi/dmu = xi/mu
        mu_slope = (dq_dmu + creep / mu * dq_dxi) / (mu * load) - ratio / mu
        solved[u] = (ratio, slope, mu_slope, State(result.p_n, result.p_t, overlap, creep))

    def miss(a: float, b: float, m: float) -> float:
        """max(|f(m) - H(m)|, |H_fine - H| at the quarter points), H the interval's Hermite and H_fine
        the one that adds m's value and slope (module docstring)."""
        points = np.array([m, 0.75 * a + 0.25 * b, 0.25 * a + 0.75 * b])

        def interpolant(keys: list[float]) -> np.ndarray:
            values, slopes = (np.array([solved[k][i] for k in keys]) for i in (0, 1))
            return hermite(np.array(keys), values, slopes, points)

        return float(np.max(np.abs(interpolant([a, m, b]) - interpolant([a, b]))))

    for u in np.linspace(lo, hi, max(initial, 2)):
        solve_at(float(u))
    nodes = sorted(solved)
    pending = list(zip(nodes[:-1], nodes[1:], strict=True))
    accepted: dict[tuple[float, float], float] = {}
    met = True
    while pending:
        a, b = pending.pop(0)
        if len(solved) + len(tested) >= budget:
            met = False
            accepted[(a, b)] = np.inf
            continue
        if b - a <= NARROWEST * (hi - lo):  # a jump of the discrete curve: not resolved by splitting
            met = False
            accepted[(a, b)] = abs(solved[b][0] - solved[a][0])
            continue
        m = 0.5 * (a + b)
        solve_at(m)
        error = MARGIN * miss(a, b, m)
        if not error <= tolerance:  # a NaN estimate (no slope recorded) is never accepted
            pending += [(a, m), (m, b)]
        else:  # accepted as it is: the midpoint only tested (module docstring)
            accepted[(a, b)] = error
            tested[m] = solved.pop(m)
    nodes = sorted(solved)
    intervals = np.array([accepted[(a, b)] for a, b in zip(nodes[:-1], nodes[1:], strict=True)])
    columns = np.array([solved[u][:3] for u in nodes])
    cases = len(solved) + len(tested)
    return Row(mu, np.array(nodes), columns[:, 0], columns[:, 1], columns[:, 2], intervals, cases, met)


def _attributes(case: Case, the_plan, rows: list[Row], t0: float) -> dict:
    """The table file's attributes besides the data and the tolerance."""
    return {
        "software_version": __version__,
        "created": utc_timestamp(),
        "title": case.title or "",
        "axis": "creepage normalised as xi R*/(mu a), with its sign (xi = (V_A - V_B)/|V|)",
        "value": "Q/(mu P): Q the tangential force on body A, P the normal load, per unit axial length",
        "met": all(row.met for row in rows),
        "creep_scale": case.friction.mu * the_plan.half_width / the_plan.radius,
        "mu": case.friction.mu,
        "half_width": the_plan.half_width,
        "radius": the_plan.radius,
        "load": float(case.normal.load or 0.0),
        "cases": sum(row.cases for row in rows),
        "time": time.perf_counter() - t0,
        "case_toml": case_to_toml(case),
    }


def _prepared(case: Case, lo: float, hi: float, tolerance: float, mu_high: float, cache: bool):
    """Check the request and build the case's plan and contact system."""
    check_request(case, lo, hi, tolerance, case.source)
    the_plan, system = pipeline.prepare(case, cache)
    scale = mu_high * the_plan.half_width / the_plan.radius
    if max(abs(lo), abs(hi)) * scale > 1.0:
        raise CaseError(
            f"--range = {lo:g}:{hi:g}: a creepage |xi| = {max(abs(lo), abs(hi)) * scale:.3g} > 1 at an end "
            f"(xi = u mu a/R*, mu a/R* = {scale:.3g}); allowed: |u| <= {1.0 / scale:.4g}",
            file=case.source,
        )
    return the_plan, system


def build(
    case: Case,
    lo: float = -1.0,
    hi: float = 1.0,
    tolerance: float = 1e-3,
    *,
    initial: int = INITIAL,
    max_cases: int = MAX_CASES,
    use_cache: bool = True,
) -> tuple[Table, np.ndarray]:
    """The table of ``case`` over u in [lo, hi] to ``tolerance`` in Q/(mu P) (module docstring);
    returns the table and the error estimate of each interval. Raises CaseError for a request
    :func:`check_request` refuses (also when |xi| would exceed 1 at an end of the range) and the
    solver's errors for a node that does not converge."""
    t0 = time.perf_counter()
    the_plan, system = _prepared(case, lo, hi, tolerance, case.friction.mu, use_cache)
    row = _row(case, system, the_plan, case.friction.mu, lo, hi, tolerance, initial, max_cases, use_cache)
    if not row.met:
        log.warning("the table reached %d solves before its error estimate met %g", row.cases, tolerance)
    attributes = _attributes(case, the_plan, [row], t0)
    table = Table(row.nodes, row.values, row.slopes, float(tolerance), float(row.intervals.max()), attributes)
    return table, row.intervals


#: Rows of the first pass of a two-axis table (equally spaced in mu).
INITIAL_ROWS = 3


def build_friction(
    case: Case,
    lo: float,
    hi: float,
    mu_low: float,
    mu_high: float,
    tolerance: float = 1e-3,
    *,
    initial: int = INITIAL,
    initial_rows: int = INITIAL_ROWS,
    max_cases: int = 20 * MAX_CASES,
    use_cache: bool = True,
    workers: int = 1,
    journal: table_rows.Journal | None = None,
    scheduler: str | None = None,
) -> tuple[FrictionTable, list[np.ndarray]]:
    """The two-axis table of ``case`` over u in [lo, hi] and mu in [mu_low, mu_high] (module docstring):
    rows of the one-axis sampling (to :data:`ROW_SHARE` of the tolerance) at friction nodes, refined in
    mu by whole mid-rows until the interpolant between two rows predicts the mid-row (its Hermite in u,
    at every node of the three rows and between them) within the rest. The estimate of the whole is the
    sum of the largest in u and in mu. The rows of a pass are solved in ``workers`` processes (one:
    here) or on the Dask cluster ``scheduler``, finished rows taken from and written to ``journal``
    (:mod:`rolling_cli.study.table_rows`).
    Returns the table and each row's interval estimates."""
    if not 0.0 < mu_low < mu_high:
        raise CaseError(f"--mu = {mu_low!r}:{mu_high!r}: allowed: LO:HI with 0 < LO < HI", file=case.source)
    t0 = time.perf_counter()
    the_plan, system = _prepared(case, lo, hi, tolerance, mu_high, use_cache)
    _PREPARED[case_to_toml(case), use_cache] = (the_plan, system)
    task = functools.partial(row_task, case, lo, hi, ROW_SHARE * tolerance, initial, use_cache)
    runner: contextlib.AbstractContextManager[table_rows.RowSolver]
    if scheduler:
        runner = table_rows.on_cluster(scheduler, task, journal)
    elif workers > 1:
        runner = table_rows.in_workers(workers, task, journal)
    else:
        runner = table_rows.in_process(task, journal)
    with runner as solve_rows:
        rows, in_mu, solves = _refine_in_mu(solve_rows, mu_low, mu_high, initial_rows, tolerance, max_cases)
    ordered = [rows[mu] for mu in sorted(rows)]
    bound = float(max(in_mu) + max(float(row.intervals.max()) for row in ordered))
    attributes = _attributes(case, the_plan, ordered, t0)
    attributes["cases"] = solves  # the kept rows' and the test rows'
    attributes["met"] = bool(attributes["met"] and bound <= tolerance)
    for key in ("mu", "creep_scale"):  # the case's own mu is not the table's: xi = u mu a/R* row by row
        attributes.pop(key)
    made = FrictionTable(tuple(_plain(row) for row in ordered), float(tolerance), bound, np.array(in_mu), attributes)
    return made, [row.intervals for row in ordered]


#: The plan and contact system of a table's case in this process (a worker builds its own once).
_PREPARED: dict[tuple[str, bool], tuple] = {}


def row_task(case: Case, lo: float, hi: float, tolerance: float, initial: int, use_cache: bool, mu: float, budget: int):
    """One row at friction ``mu`` (:func:`_row`, at most ``budget`` solves), where it runs: in this process
    or a worker (which prepares the case's plan and contact system once; picklable)."""
    key = (case_to_toml(case), use_cache)
    if key not in _PREPARED:
        _PREPARED.clear()
        _PREPARED[key] = pipeline.prepare(case, use_cache)
    the_plan, system = _PREPARED[key]
    return _row(case, system, the_plan, mu, lo, hi, tolerance, initial, budget, use_cache)


def _refine_in_mu(solve_rows, mu_low: float, mu_high: float, initial_rows: int, tolerance: float, max_cases: int):
    """The rows kept (mu -> Row), the estimate of each interval between them and the solves made:
    passes of mid-rows (module docstring), each pass's rows solved together by ``solve_rows``."""
    rows: dict[float, Row] = {}
    solves = 0

    def solve(friction: list[float]) -> list[Row]:  # whole rows (a pass may end past max_cases)
        nonlocal solves
        out = solve_rows(friction, MAX_CASES)
        solves += sum(row.cases for row in out)
        return out

    first = [float(mu) for mu in np.linspace(mu_low, mu_high, max(initial_rows, 2))]
    rows.update((row.mu, row) for row in solve(first))
    friction = sorted(rows)
    pending = list(zip(friction[:-1], friction[1:], strict=True))
    accepted: dict[tuple[float, float], float] = {}
    while pending:
        batch = []
        for a, b in pending:
            if solves >= max_cases:
                accepted[(a, b)] = np.inf
            elif b - a <= NARROWEST * (mu_high - mu_low):  # a jump in mu: the largest difference of the rows
                u = _probes(_plain(rows[a]), _plain(rows[b]))
                below, above = (hermite(r.nodes, r.values, r.slopes, u) for r in (rows[a], rows[b]))
                accepted[(a, b)] = float(np.max(np.abs(above - below)))
            else:
                batch.append((a, b))
        pending = []
        for (a, b), row in zip(batch, solve([0.5 * (a + b) for a, b in batch]) if batch else [], strict=True):
            middle, low, high = _plain(row), _plain(rows[a]), _plain(rows[b])
            u = _probes(low, high, middle)
            error = MARGIN_MU * _miss_in_mu(low, middle, high, u)
            if not error <= (1.0 - ROW_SHARE) * tolerance:  # split (also on NaN): the mid-row is kept
                rows[row.mu] = row
                pending += [(a, row.mu), (row.mu, b)]
            else:  # accepted as it is: the mid-row only tested (module docstring)
                accepted[(a, b)] = error
    friction = sorted(rows)
    return rows, [accepted[(a, b)] for a, b in zip(friction[:-1], friction[1:], strict=True)], solves


def _miss_in_mu(low: TableRow, middle: TableRow, high: TableRow, u: np.ndarray) -> float:
    """The interval (low, high)'s miss in mu at the probes u (module docstring): the mid-row against the
    interpolant between low and high, and at the quarter rows the interpolants through the mid-row
    (its values and slopes in mu) against it."""
    quarter = 0.25 * (high.mu - low.mu)
    whole = between(low, high, u, np.full(u.size, middle.mu))
    out = float(np.max(np.abs(hermite(middle.nodes, middle.values, middle.slopes, u) - whole)))
    for below, above, mu in ((low, middle, low.mu + quarter), (middle, high, high.mu - quarter)):
        at = np.full(u.size, mu)
        out = max(out, float(np.max(np.abs(between(below, above, u, at) - between(low, high, u, at)))))
    return out


def _probes(*rows: TableRow) -> np.ndarray:
    """Where a mid-row is compared with the rows around it: every node of the three and the midpoints
    between neighbouring ones (the interpolant in mu is tested inside the cells in u too)."""
    nodes = np.unique(np.concatenate([row.nodes for row in rows]))
    return np.sort(np.concatenate([nodes, 0.5 * (nodes[1:] + nodes[:-1])]))


def _plain(row: Row) -> TableRow:
    return TableRow(row.mu, row.nodes, row.values, row.slopes, row.mu_slopes)
