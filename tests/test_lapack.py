"""The kept LU of the Newton's last step (issue 24: sensitivities at <= 10 % of a solve).

rolling_cli/solver/lapack.py calls numpy's own getrf/getrs; rolling_cli/solver/linalg.Factor
keeps an LU; rolling_cli/solver/reduced.newton_point keeps the last one and
rolling_cli/solver/kept.kept_system hands it to the sensitivities, as it is or bordered.
References: numpy.linalg.solve (the numbers the Newton had before, bit for bit) and a fresh
assembly and factorisation of the same reduced system.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from helpers import dissimilar
from rolling_cli import pipeline
from rolling_cli.case import load_case
from rolling_cli.solver import kept, lapack, linalg, reduced, sensitivity
from rolling_cli.solver.formulation import Problem, State, evaluate, node_sets, traction_scales

CASES = Path(__file__).resolve().parents[1] / "cases"


def _recorded_newton(monkeypatch, data: dict):
    """Solve ``data``, recording every Newton matrix and right-hand side (copies)."""
    seen = []
    original = linalg.factorise

    def record(matrix):
        factor = original(matrix)
        seen.append(matrix.copy())
        return factor

    monkeypatch.setattr(reduced, "factorise", record)
    case = load_case(data)
    _, system = pipeline.prepare(case)
    result = pipeline.solve(case, system=system)
    return seen, system, result


def test_numpy_lapack_found():
    """This project's environment (numpy's wheel) has the library; its load-time check passed."""
    assert lapack.available()


def test_factor_gives_numpy_solve_bits(monkeypatch):
    """Every Newton matrix of a coupled solve, and random right-hand sides: the kept LU's solve is
    numpy.linalg.solve's, bit for bit (the Newton's numbers do not change), for one column and for
    several (the sensitivities' columns: gesv with the same columns)."""
    seen, _, result = _recorded_newton(monkeypatch, dissimilar(**{"discretization.contact_elements": 60}))
    assert result.converged and len(seen) >= 2
    rng = np.random.default_rng(0)
    for matrix in seen:
        b = rng.standard_normal(matrix.shape[0])
        columns = rng.standard_normal((matrix.shape[0], 3))
        factor = linalg.factorise(matrix)
        assert factor is not None
        assert np.array_equal(factor.solve(b), np.linalg.solve(matrix, b))
        assert np.array_equal(factor.solve(columns), np.linalg.solve(matrix, columns))
        assert np.array_equal(factor.matrix, matrix)  # A itself is kept unchanged


def test_without_numpy_lapack_the_solve_is_unchanged(monkeypatch):
    """Another numpy build (no library found, or its check failed): nothing is kept, the Newton
    solves with numpy.linalg.solve, and the result is the same bit for bit (the kept LU gives
    numpy.linalg.solve's numbers, test above), sensitivities included up to their rounding."""
    data = dissimilar(**{"discretization.contact_elements": 60, "tangential.q_over_mu_p": 0.6})
    _, _, with_lapack = _recorded_newton(monkeypatch, data)
    monkeypatch.setattr(lapack, "available", lambda: False)
    assert linalg.factorise(np.eye(4)) is None
    _, _, without = _recorded_newton(monkeypatch, data)
    assert without.converged and without.iterations == with_lapack.iterations
    for name in ("p_n", "p_t"):
        assert np.array_equal(getattr(without, name), getattr(with_lapack, name))
    assert without.creep == with_lapack.creep
    assert without.dQ_dxi == pytest.approx(with_lapack.dQ_dxi, rel=1e-9)


def test_singular_matrix_raises():
    """An exactly singular matrix: the solver's one-line LinAlgError, as numpy.linalg.solve gives."""
    with pytest.raises(np.linalg.LinAlgError, match="singular Newton system"):
        linalg.factorise(np.zeros((3, 3)))


def _problem(system, result, data_force: bool) -> tuple[Problem, State]:
    state = State(result.p_n, result.p_t, result.solved_overlap, result.creep)
    load = float(-(system.weights @ state.p_n))
    force = ("load", float(system.weights @ state.p_t)) if data_force else None
    return Problem(system, "coupled", result.mu, load=load, force=force), state


def test_sensitivities_reuse_the_last_newton_lu(monkeypatch):
    """After a converged coupled solve the sensitivities take the Newton's last matrix and LU
    (kept_system's factor set, and then released), and the derivatives equal those of a fresh
    assembly and LU of the same system within rounding: both are exact solves of the same
    matrix, so they differ by the LU's backward error times the condition number, ~1e-12 on
    these ~120-unknown systems (measured: equal to the last bit here); 1e-9 leaves room."""
    data = dissimilar(**{"discretization.contact_elements": 60, "tangential.q_over_mu_p": 0.6})
    used = []
    original = kept.kept_system

    def spy(*args):
        out = original(*args)
        used.append(out.factor is not None)
        return out

    monkeypatch.setattr(kept, "kept_system", spy)
    _, system, result = _recorded_newton(monkeypatch, data)
    assert used == [True]
    assert reduced._KEPT is None  # released once taken
    # a fresh assembly: nothing kept now
    problem, state = _problem(system, result, True)
    fresh = sensitivity.sensitivities(system, result.mu, state, True)
    assert used == [True, False]
    for name, value in fresh.as_dict().items():
        if name in ("dQ_dP", "dxi_dP", "da_dP", "dp0_dP"):
            continue  # the result's come from the load homogeneity (self-similar), not this call's
        assert getattr(result, name) == pytest.approx(value, rel=1e-9, abs=0.0), name


def test_kept_system_refuses_another_matrix(monkeypatch):
    """Node sets other than the kept step's (one adhesion node fewer) fix another matrix: it is
    assembled afresh (no factor) and equals reduced_system's."""
    data = dissimilar(**{"discretization.contact_elements": 60, "tangential.q_over_mu_p": 0.6})
    case = load_case(data)
    _, system = pipeline.prepare(case)
    monkeypatch.setattr(sensitivity, "sensitivities", lambda *a, **k: sensitivity.UNDEFINED)
    result = pipeline.solve(case, system=system)
    assert reduced._KEPT is not None
    problem, state = _problem(system, result, True)
    ev = evaluate(problem, state, traction_scales(problem, state))
    sets = node_sets(problem, state, ev)
    assert sets.stick.size > 1
    fewer = type(sets)(sets.contact, sets.stick[1:], np.union1d(sets.slip, sets.stick[:1]), sets.sigma)
    other = kept.kept_system(problem, state, fewer, ev)
    assert other.factor is None
    assert np.array_equal(other.matrix, reduced.reduced_system(problem, state, fewer, ev).matrix)


def test_bordered_system_equals_the_assembled_one(monkeypatch):
    """An overlap-controlled coupled solve with Q/(mu P) prescribed (cases/paper_fig5_q075: BEM
    bodies, 63 nodes; the layers of cases/tyred_* are the same kind): the sensitivities'
    load-controlled matrix is the Newton's bordered (kept.Bordered); its solves equal a fresh LU
    of the assembled matrix within rounding: block
    elimination through a stable LU, errors ~ eps cond(A) (measured 2e-16, residual 6e-14); 1e-9
    of the largest entry leaves room."""
    case = load_case(CASES / "paper_fig5_q075.toml")
    _, system = pipeline.prepare(case)
    monkeypatch.setattr(sensitivity, "sensitivities", lambda *a, **k: sensitivity.UNDEFINED)
    result = pipeline.solve(case, system=system)
    assert result.converged and reduced._KEPT is not None and reduced._KEPT[2].col_overlap is None
    problem, state = _problem(system, result, True)
    ev = evaluate(problem, state, traction_scales(problem, state))
    sets = node_sets(problem, state, ev)
    bordered = kept.kept_system(problem, state, sets, ev)
    assert isinstance(bordered.factor, kept.Bordered)
    assembled = reduced.reduced_system(problem, state, sets, ev).matrix
    assert isinstance(assembled, np.ndarray)
    columns = np.random.default_rng(1).standard_normal((assembled.shape[0], 3))
    z = bordered.factor.solve(columns)
    assert np.abs(z - np.linalg.solve(assembled, columns)).max() <= 1e-9 * np.abs(z).max()
    assert np.abs(assembled @ z - columns).max() <= 1e-9 * np.abs(columns).max()
