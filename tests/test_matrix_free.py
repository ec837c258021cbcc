"""The matrix-free Newton path (issue #14 item 2) against the dense one.

The fast path holds the half-plane blocks as block-Toeplitz operators and solves
each Newton step by GMRES with the near field's LU as preconditioner. Its
entries are the dense path's; its products, reduced system and solutions agree
with the dense ones to round-off; a whole solve gives the dense path's result to
1e-8 (the issue's requirement; both stop on the same residual tolerance with the
same node states, and the last Newton step of either is solved to the round-off
floor, so they differ by round-off only: measured ~1e-11).
"""

import numpy as np
import pytest

from helpers import case_dict, dissimilar
from rolling_cli import pipeline
from rolling_cli.case import load_case
from rolling_cli.influence import build, halfplane
from rolling_cli.model.grid import ContactGrid
from rolling_cli.solver import coarse, formulation, krylov, matrix_free, near_field, reduced
from rolling_cli.solver.banded import BorderedBandLU, SparseLU
from rolling_cli.solver.formulation import State
from rolling_cli.solver.system import build_system

EPS = np.finfo(float).eps


@pytest.fixture
def operators_from(monkeypatch):
    """Set the size from which half-plane grids get operators (and forget memoised influences)."""

    def set_threshold(nodes: int) -> None:
        monkeypatch.setattr(halfplane, "OPERATOR_NODES", nodes)
        build.clear_memo()

    yield set_threshold
    build.clear_memo()


def _solve(data):
    return pipeline.solve(load_case(data))


CASES = {
    # 1200 nodes, decoupled: the normal problem, then the tangential one with Q/(mu P) prescribed
    "Carter": case_dict(**{"discretization.contact_elements": 400}),
    # 750 nodes, coupled force control (and a coarse grid level first)
    "dissimilar": dissimilar(**{"discretization.contact_elements": 250, "tangential.q_over_mu_p": 0.75}),
    # 900 nodes, the creepage prescribed
    "creep": case_dict(**{"discretization.contact_elements": 300, "tangential.creep": -4.0e-4}),
}


@pytest.mark.parametrize("name", list(CASES))
def test_fast_path_gives_the_dense_result(name, operators_from):
    operators_from(10**9)
    dense = _solve(CASES[name])
    operators_from(1)
    fast = _solve(CASES[name])
    scale = np.abs(dense.p_n).max()
    mu = dense.attributes["mu"]
    assert np.max(np.abs(fast.p_n - dense.p_n)) <= 1e-8 * scale
    assert np.max(np.abs(fast.p_t - dense.p_t)) <= 1e-8 * mu * scale
    assert abs(fast.creep - dense.creep) <= 1e-8 * abs(dense.creep)
    assert np.array_equal(fast.state, dense.state)
    assert fast.attributes["residual"] <= fast.attributes["tolerance_applied"]
    assert dense.attributes["linear_solver"] == "dense LU" and "krylov_iterations" not in dense.attributes
    assert fast.attributes["linear_solver"] == "Krylov" and fast.attributes["krylov_iterations"] > 0
    assert fast.attributes["krylov_dense_fallbacks"] == 0  # every step by GMRES itself
    assert {row["linear_solver"] for row in fast.history} == {"Krylov"}
    assert {row["linear_solver"] for row in dense.history} == {"dense LU"}


def test_the_path_is_chosen_by_size():
    """Uniform grids from OPERATOR_NODES nodes up get operators; graded grids never (no Toeplitz structure)."""
    limit = halfplane.OPERATOR_NODES
    assert not halfplane.use_operators(ContactGrid(1.5, limit // 3 - 1, 2))
    assert halfplane.use_operators(ContactGrid(1.5, limit // 3, 2))
    assert halfplane.use_operators(ContactGrid(1.5, limit, 0))
    uniform = ContactGrid(1.5, limit, 2)
    graded = ContactGrid.graded(uniform.edges + 0.1 * uniform.element_length * np.sin(np.arange(limit + 1)) ** 2)
    assert not graded.uniform and not halfplane.use_operators(graded)
    small = _solve(case_dict(**{"discretization.contact_elements": limit // 3 - 1}))
    large = _solve(case_dict(**{"discretization.contact_elements": limit // 3}))
    assert small.attributes["linear_solver"] == "dense LU"
    assert large.attributes["linear_solver"] == "Krylov"


def _reduced_pair(data, mode: str):
    """Dense and matrix-free reduced systems of one converged state, with their problem."""
    case = load_case(data)
    the_plan = pipeline.plan(case)
    grid = the_plan.grid
    args = (grid, case.bodies.A.modulus, case.bodies.A.ratio, case.bodies.B.modulus, case.bodies.B.ratio)
    coupled = the_plan.effects.coupling
    systems = [
        build_system(halfplane.pair_compliance(*args, coupled, operators=flag), the_plan.radius, -1, grid)
        for flag in (False, True)
    ]
    result = pipeline.solve(case, system=systems[0])
    state = State(result.p_n, result.p_t, result.attributes["solved_overlap"], result.creep)
    out = []
    for system in systems:
        task = pipeline._task(case, the_plan, system)
        problem = task.problem(mode)
        ev = formulation.evaluate(problem, state, formulation.traction_scales(problem, state))
        sets = formulation.node_sets(problem, state, ev)
        out.append(reduced.reduced_system(problem, state, sets, ev))
    return out


MODES = [
    (dissimilar(**{"discretization.contact_elements": 200, "tangential.q_over_mu_p": 0.75}), "coupled"),
    (case_dict(**{"discretization.contact_elements": 200}), "normal"),
    (case_dict(**{"discretization.contact_elements": 200}), "tangential"),
]


@pytest.mark.parametrize("data,mode", MODES)
def test_reduced_operator_is_the_dense_reduced_system(data, mode):
    dense, fast = _reduced_pair(data, mode)
    A = dense.matrix
    op = fast.matrix
    assert isinstance(op, matrix_free.ReducedOperator) and op.shape == A.shape
    assert (fast.col_overlap, fast.col_creep) == (dense.col_overlap, dense.col_creep)
    rng = np.random.default_rng(5)
    z = rng.standard_normal(A.shape[0])
    # FFT products: 10 eps log2(L) of the magnitudes summed (tests/test_toeplitz.py)
    length = op.problem.system.S_nn.transform_length
    bound = 10 * EPS * np.log2(length) * (np.abs(A) @ np.abs(z))
    assert np.all(np.abs(op @ z - A @ z) <= bound + 1e-300)
    rhs_scale = np.max(np.abs(dense.rhs))
    assert np.max(np.abs(fast.rhs - dense.rhs)) <= 10 * EPS * np.log2(length) * 10 * rhs_scale
    # entries of E A, rows scaled: the same values, added in another order
    core = A.shape[0] - (fast.col_overlap is not None) - (fast.col_creep is not None)
    scaled = op.row_scale[:, None] * A
    diff = np.flatnonzero(op._differenced())
    scaled[diff] -= scaled[diff + 1]
    i, j = np.meshgrid(np.arange(core), np.arange(core), indexing="ij")
    tolerance = 100 * EPS * np.abs(scaled).max()
    assert np.allclose(op.entries(i.ravel(), j.ravel()), scaled[:core, :core].ravel(), rtol=0, atol=tolerance)
    border, columns, rows, _ = op.borders()
    assert np.array_equal(scaled[:core][:, border], columns) and np.array_equal(scaled[border][:, :core], rows)
    # the Krylov solve to its round-off target against LU: 1e-9 of the solution (targets ~1e-13, measured 1e-12)
    exact = np.linalg.solve(A, dense.rhs)
    found = reduced.solve_reduced(fast, fast.rhs)
    assert np.max(np.abs(found - exact)) <= 1e-9 * np.max(np.abs(exact))
    residual = op.row_scale * (fast.rhs - op @ found)
    assert np.max(np.abs(residual)) <= matrix_free.STAGNATION_ALLOWANCE * op.target
    if dense.creep_column is not None:
        assert np.array_equal(fast.creep_column, dense.creep_column)
    # the dense fallback (E D A assembled from the exact entries): the LU's solution, to 1e-9 as above
    assert np.max(np.abs(op.solve_dense(fast.rhs) - exact)) <= 1e-9 * np.max(np.abs(exact))


@pytest.mark.parametrize("data,mode", MODES)
def test_band_assembly_is_the_entries(data, mode):
    """The preconditioner's band, assembled diagonal by diagonal from slices, holds exactly the
    operator's entries (:meth:`ReducedOperator.entries`: tested against the dense matrix above)."""
    _, fast = _reduced_pair(data, mode)
    op = fast.matrix
    order, per_node = near_field.band_order(op)
    for width in (2, matrix_free.NEAR_FIELD):
        half = min(per_node * width + per_node - 1, order.size - 1)
        assert np.array_equal(near_field._band(op, order, half), near_field._band_from_entries(op, order, half))


def test_a_stalled_krylov_solve_falls_back_to_dense_lu(monkeypatch):
    """A GMRES that stalls: up to DENSE_FALLBACK unknowns the step is solved by dense LU (and
    counted), above it the solve fails (LinAlgError: the Newton strategies handle it)."""
    dense, fast = _reduced_pair(*MODES[0])
    exact = np.linalg.solve(dense.matrix, dense.rhs)

    def stalled(apply, rhs, precondition, target, start=None):
        return krylov.KrylovResult(np.zeros_like(rhs), 1, 1.0, False)

    monkeypatch.setattr(matrix_free.krylov, "gmres", stalled)
    record: dict = {}
    found = reduced.solve_reduced(fast, fast.rhs, record=record)
    assert np.max(np.abs(found - exact)) <= 1e-9 * np.max(np.abs(exact))
    assert record == {"krylov_iterations": 1, "krylov_dense_fallbacks": 1}
    monkeypatch.setattr(matrix_free, "DENSE_FALLBACK", fast.matrix.shape[0] - 1)
    with pytest.raises(np.linalg.LinAlgError):
        reduced.solve_reduced(fast, fast.rhs)


def test_inexact_newton_forcing():
    """Two digits from a rough iterate, the round-off floor (target 0) from a close one."""
    assert matrix_free.forcing_target(0.3) == pytest.approx(matrix_free.FORCING * 0.3)
    assert matrix_free.forcing_target(0.5 * matrix_free.FORCING_FROM) == 0.0
    _, fast = _reduced_pair(*MODES[0])
    assert fast.matrix.target >= matrix_free.KRYLOV_TOLERANCE


def test_gmres_reaches_its_target():
    rng = np.random.default_rng(11)
    n = 120
    A = np.eye(n) * 4.0 + rng.standard_normal((n, n)) / np.sqrt(n)
    b = rng.standard_normal(n)
    diagonal = np.diag(A).copy()
    found = krylov.gmres(lambda x: A @ x, b, lambda v: v / diagonal, 1e-12, restart=30)
    assert found.converged and found.residual <= 1e-12
    assert np.max(np.abs(b - A @ found.x)) == found.residual
    assert np.allclose(found.x, np.linalg.solve(A, b), rtol=0, atol=1e-11)
    again = krylov.gmres(lambda x: A @ x, b, lambda v: v / diagonal, 1e-10, start=found.x)
    assert again.iterations == 0 and again.converged
    # a preconditioner in single precision (not exactly linear): flexible GMRES still reaches 1e-12
    single = diagonal.astype(np.float32)
    rough = krylov.gmres(lambda x: A @ x, b, lambda v: (v.astype(np.float32) / single).astype(float), 1e-12)
    assert rough.converged and np.max(np.abs(b - A @ rough.x)) <= 1e-12
    # a target below round-off: GMRES stops when a cycle no longer halves the residual
    stuck = krylov.gmres(lambda x: A @ x, b, lambda v: v / diagonal, 0.0)
    assert not stuck.converged and stuck.residual < 1e-13 and stuck.iterations < 600


def _bordered(n: int, singular: bool):
    rng = np.random.default_rng(4)
    lower, upper = 3, 2
    K = np.zeros((n, n))
    for d in range(-lower, upper + 1):
        K += np.diag(rng.standard_normal(n - abs(d)), d)
    K += 6.0 * np.eye(n)
    if singular:
        K[:, 7] = 0.0  # K singular; the border rows make M regular
    U, V = rng.standard_normal((n, 2)), rng.standard_normal((2, n))
    if singular:
        U[:, 0] = 0.0
        U[7, 0] = 1.0
        V[0] = 0.0
        V[0, 7] = 1.0
    D = np.zeros((2, 2))
    band = np.zeros((2 * lower + upper + 1, n), order="F")
    for j in range(n):
        for i in range(max(0, j - upper), min(n, j + lower + 1)):
            band[lower + upper + i - j, j] = K[i, j]
    return np.block([[K, U], [V, D]]), band, lower, upper, U, V, D


def test_bordered_band_lu_and_its_fallback():
    M, band, lower, upper, U, V, D = _bordered(40, singular=False)
    rhs = np.random.default_rng(6).standard_normal(42)
    factor = BorderedBandLU(band, lower, upper, U, V, D)
    core, edge = factor.solve(rhs[:40], rhs[40:])
    exact = np.linalg.solve(M, rhs)
    scale = np.linalg.cond(M) * EPS * np.abs(exact).max()
    assert np.allclose(np.concatenate([core, edge]), exact, rtol=0, atol=100 * scale)
    # single precision (the preconditioner's): the same solution to float32 round-off times cond(M)
    _, band, *_ = _bordered(40, singular=False)
    single = BorderedBandLU(band, lower, upper, U, V, D, single=True)
    core, edge = single.solve(rhs[:40], rhs[40:])
    tiny = np.linalg.cond(M) * np.finfo(np.float32).eps * np.abs(exact).max()
    assert np.allclose(np.concatenate([core, edge]), exact, rtol=0, atol=100 * tiny)
    assert not np.allclose(np.concatenate([core, edge]), exact, rtol=0, atol=100 * scale)  # really float32
    M, band, lower, upper, U, V, D = _bordered(40, singular=True)
    with pytest.raises(np.linalg.LinAlgError):
        BorderedBandLU(band, lower, upper, U, V, D)
    rows, cols = np.nonzero(M)
    solved = SparseLU(rows, cols, M[rows, cols], 42).solve(rhs)
    exact = np.linalg.solve(M, rhs)
    assert np.allclose(solved, exact, rtol=0, atol=100 * np.linalg.cond(M) * EPS * np.abs(exact).max())


@pytest.mark.parametrize("data,mode", MODES)
def test_coarse_matrix_is_the_galerkin_product(data, mode):
    """A_c of the two-level preconditioner, assembled from corner sums of the influence operators,
    equals P^T A P computed column by column from the operator's FFT products (the aggregates are
    runs of one traction and one slip coefficient: A P is exact on them). Both sides carry
    round-off: the products 10 eps log2(L) of the magnitudes summed (as above), the corner sums a
    few eps of the twice cumulated offset values (tests/test_toeplitz.py); 1e-11 of max |A_c|
    holds both with a margin of ~10 (measured ~1e-13)."""
    _, fast = _reduced_pair(data, mode)
    op = fast.matrix

    def apply(z):
        return op.row_scale * (op @ z)

    starts, traction, border, matrix = coarse.galerkin(op, apply)
    assert starts.size > 10 and traction == op.shape[0] - border.size
    counts = np.diff(np.append(starts, traction))
    assert counts.min() >= 1 and counts.max() <= coarse.aggregate_nodes(traction, 3)
    size = matrix.shape[0]
    columns = np.column_stack([coarse.prolong(e, starts, traction) for e in np.eye(size)])
    assert np.array_equal(columns.sum(axis=1), np.ones(op.shape[0]))  # a partition of the unknowns
    product = np.column_stack([coarse.restrict(apply(c), starts, traction, border) for c in columns.T])
    assert np.abs(matrix - product).max() <= 1e-11 * np.abs(product).max()
    assert np.array_equal(
        coarse.restrict(np.arange(op.shape[0], dtype=float), starts, traction, border),
        columns.T @ np.arange(op.shape[0]),
    )


def test_two_level_preconditioner_on_a_coupled_case(monkeypatch):
    """3,000 nodes, coupled, from zero to the round-off target: GMRES with the coarse correction
    after the band takes a third of the iterations of the band alone or fewer (the band misses the
    log kernel's smooth far field, which the coarse grid holds; the gap grows with the grid:
    benchmarks/RESULTS.md), and both reach the dense LU's solution of the same Newton system (E D A
    from the exact entries, tested above) to 1e-8: the round-off target ~1e-13 of the scaled
    residual, times the system's conditioning (measured ~1e-11)."""
    monkeypatch.setattr(halfplane, "OPERATOR_NODES", 900)
    build.clear_memo()
    data = dissimilar(**{"discretization.contact_elements": 1000, "tangential.q_over_mu_p": 0.75})
    case = load_case(data)
    the_plan = pipeline.plan(case)
    grid = the_plan.grid
    args = (grid, case.bodies.A.modulus, case.bodies.A.ratio, case.bodies.B.modulus, case.bodies.B.ratio)
    system = build_system(halfplane.pair_compliance(*args, True, operators=True), the_plan.radius, -1, grid)
    result = pipeline.solve(case, system=system)
    assert result.attributes["krylov_dense_fallbacks"] == 0
    state = State(result.p_n, result.p_t, result.attributes["solved_overlap"], result.creep)
    problem = pipeline._task(case, the_plan, system).problem("coupled")
    ev = formulation.evaluate(problem, state, formulation.traction_scales(problem, state))
    fast = reduced.reduced_system(problem, state, formulation.node_sets(problem, state, ev), ev)
    op = fast.matrix
    assert isinstance(op, matrix_free.ReducedOperator) and op.stick.size and op.col_creep is not None
    exact = op.solve_dense(fast.rhs)

    def apply(z):
        return op.row_scale * (op @ z)

    rhs = op.row_scale * fast.rhs
    band = near_field.preconditioner(op, matrix_free.NEAR_FIELD)
    two = op.preconditioner(apply)
    found = {}
    for name, precondition in (("band", band), ("two-level", two)):
        found[name] = krylov.gmres(apply, rhs, precondition, op.target, max_iterations=2000)
    alone, both = found["band"], found["two-level"]
    assert both.iterations * 3 <= alone.iterations  # measured 20 against 79
    for run in (alone, both):
        assert run.residual <= matrix_free.STAGNATION_ALLOWANCE * op.target
        assert np.max(np.abs(run.x - exact)) <= 1e-8 * np.max(np.abs(exact))
    build.clear_memo()


def test_krylov_counts_belong_to_each_solve(operators_from):
    """Three solves on one prebuilt system (as a sweep chunk runs them) each report their own
    Krylov counts, the sums of their Newton history's columns; they once accumulated in a
    module-level table keyed on the system (3, 6, 9 solves for 3 Newton iterations each)."""
    operators_from(1)
    case = load_case(CASES["creep"])
    the_plan, system = pipeline.prepare(case)
    results = [pipeline.solve(case, system=system) for _ in range(3)]
    for result in results:
        steps = [row for row in result.history if "krylov_iterations" in row]
        assert result.attributes["krylov_solves"] == len(steps) > 0
        assert result.attributes["krylov_iterations"] == sum(row["krylov_iterations"] for row in steps)
    counts = {(r.attributes["krylov_solves"], r.attributes["krylov_iterations"]) for r in results}
    assert len(counts) == 1  # the same case solved three times: the same counts
