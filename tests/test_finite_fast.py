"""The finite roller's whole-process speed-ups (issue 21, "Numbers to reach"): the contact blocks
gathered by strided runs, the arc rotation by whole-array products, the mirror halves solved at
once, and the console's reuse of freed memory. Each against an independent formulation."""

import os
import subprocess
import sys
import textwrap
import threading

import numpy as np
import pytest

from rolling_cli.influence.bem import condense, cylinder
from rolling_cli.influence.bem.system import MixedSystem
from rolling_cli.model.grid import ContactGrid


def _indices():
    """Index arrays of every shape :func:`condense.runs` meets: a mirror half's (one run down, one
    up), a whole system's (one run), constant stretches (zeros where a half has no parameter),
    single values, and random ones (mostly runs of one)."""
    rng = np.random.default_rng(3)
    return [
        np.concatenate([np.arange(9, -1, -1), np.arange(10)]),
        np.arange(17),
        np.array([4]),
        np.array([0, 0, 0, 1, 2, 5, 4, 3, 3]),
        np.array([5, 6, 5, 4, 7, 9, 11]),
        rng.integers(0, 30, size=40),
    ]


@pytest.mark.parametrize("index", _indices())
def test_runs_cover_the_index(index):
    """The runs, read back through their slices, give the index array itself, with steps +-1 only."""
    rebuilt = np.full(index.size, -1)
    source = np.arange(100)
    for target, values in condense.runs(index):
        rebuilt[target] = source[values]
        assert values.step in (1, -1)
    assert np.array_equal(rebuilt, index)


@pytest.mark.parametrize("rows", _indices())
def test_gather_is_fancy_indexing(rows):
    """:func:`condense._gather` against numpy's np.ix_ indexing, exactly (a copy either way); the
    random index has more runs than ``_MAX_RUNS`` and takes np.ix_ itself."""
    matrix = np.random.default_rng(5).standard_normal((30, 30))
    cols = _indices()[0]
    gathered = condense._gather(matrix, rows, cols, condense.runs(cols))
    assert np.array_equal(gathered, matrix[np.ix_(rows, cols)])


def test_arc_blocks_match_the_tensor_contraction():
    """The arc-frame blocks by whole-array products against the contraction
    sum_kl left[i, k] C[i, k, j, l] right[j, l] by einsum, with other load angles: within 1e-14 of
    the largest entry (each entry is a sum of four products of terms up to max|C|, so a few
    rounding units of it)."""
    rng = np.random.default_rng(7)
    n = 23
    xy = rng.standard_normal((n, 2, n, 2))
    theta, loads = rng.uniform(-0.4, 0.4, n), rng.uniform(-0.4, 0.4, n)
    nu = np.column_stack([np.sin(theta), np.cos(theta)])
    tau = np.column_stack([np.cos(theta), -np.sin(theta)])
    nu_l = np.column_stack([np.sin(loads), np.cos(loads)])
    tau_l = np.column_stack([np.cos(loads), -np.sin(loads)])
    expected = {
        "S_tt": np.einsum("ik,ikjl,jl->ij", tau, xy, tau_l),
        "S_tn": np.einsum("ik,ikjl,jl->ij", tau, xy, nu_l),
        "S_nt": -np.einsum("ik,ikjl,jl->ij", nu, xy, tau_l),
        "S_nn": -np.einsum("ik,ikjl,jl->ij", nu, xy, nu_l),
    }
    got = cylinder.rotate(xy, theta, loads)
    for name, block in expected.items():
        assert np.abs(got[name] - block).max() <= 1e-14 * np.abs(xy).max()


def test_condensed_matches_the_xy_route():
    """:func:`cylinder.condensed` (blocks rotated straight from the frame blocks, the y rows' sign on
    the directions) against the public route, the xy compliance (n_c, 2, n_c, 2) rotated: the
    same numbers to rounding (1e-14 of the largest entry, as above)."""
    grid = ContactGrid(0.6, 12, 2)
    mesh = cylinder.annulus_mesh(grid, 5.0, 4.0)
    direct = cylinder.condensed(grid, 5.0, 4.0, 10.0, 0.45)
    xy = cylinder.xy_compliance(mesh, grid, 10.0, 0.45, radius=5.0)
    rotated = cylinder.rotate(xy, cylinder.contact_angles(mesh, 5.0))
    for name, block in rotated.items():
        assert np.abs(getattr(direct, name) - block).max() <= 1e-14 * np.abs(xy).max()


def _systems(size: int, singular: bool = False) -> list[MixedSystem]:
    rng = np.random.default_rng(11)
    out = []
    for k in range(2):
        a = rng.standard_normal((size, size)) + size * np.eye(size)
        if singular and k == 1:
            a[:, 0] = 0.0
        out.append(MixedSystem(np.asfortranarray(a), np.asfortranarray(rng.standard_normal((size, 5)))))
    return out


def test_halves_at_once_give_the_sequential_numbers(monkeypatch):
    """Two systems of ``PARALLEL_SYSTEM`` unknowns: the second is solved in another thread, and both
    solutions equal numpy's own solves in turn bit for bit (one BLAS thread: the same LAPACK
    calls on the same arrays)."""
    from threadpoolctl import threadpool_limits

    size = condense.PARALLEL_SYSTEM
    monkeypatch.setattr(condense, "_cpus", lambda: 2)
    threads = []
    inner = condense._solve_one

    def recorded(system):
        threads.append(threading.current_thread().name)
        return inner(system)

    monkeypatch.setattr(condense, "_solve_one", recorded)
    with threadpool_limits(limits=1):
        expected = [np.linalg.solve(s.matrix, s.rhs) for s in _systems(size)]
        systems = _systems(size)
        got = condense.solve_all(systems)
    assert systems == [] and sorted(threads) == ["MainThread", "bem-half"]
    assert all(np.array_equal(x, y) for x, y in zip(got, expected, strict=True))


def test_halves_at_once_raise_the_threads_error(monkeypatch):
    """A singular second half, solved in the other thread, raises in the caller as in turn."""
    monkeypatch.setattr(condense, "_cpus", lambda: 2)
    with pytest.raises(np.linalg.LinAlgError, match="singular"):
        condense.solve_all(_systems(condense.PARALLEL_SYSTEM, singular=True))


def test_small_or_single_cpu_systems_are_solved_in_turn(monkeypatch):
    """Below ``PARALLEL_SYSTEM``, or with one CPU, no second thread."""
    started = []
    monkeypatch.setattr(threading.Thread, "start", lambda self: started.append(self))
    monkeypatch.setattr(condense, "_cpus", lambda: 2)
    condense.solve_all(_systems(20))
    monkeypatch.setattr(condense, "_cpus", lambda: 1)
    condense.solve_all(_systems(condense.PARALLEL_SYSTEM))
    assert started == []


_FAULTS = """
import resource, sys
import numpy as np
from rolling_cli import process
if sys.argv[1] == "reuse":
    process.reuse_freed_memory()
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for k in range(40):
    a = np.ones(int(300_000 * 1.02**k))  # 2.4 MB growing to 5.3 MB, each freed before the next
    del a
print(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
"""


def _glibc() -> bool:
    import platform

    return sys.platform.startswith("linux") and platform.libc_ver()[0] == "glibc"


@pytest.mark.skipif(not _glibc(), reason="mallopt's thresholds are glibc's")
@pytest.mark.skipif(
    any(name.startswith("MALLOC_") for name in os.environ), reason="the user's MALLOC_* settings replace the defaults"
)
def test_console_reuses_freed_memory():
    """40 arrays, each 2 % larger than the last (2.4 to 5.3 MB), allocated and freed in turn: with the
    console's malloc settings the heap keeps the freed block and each array faults in only its
    growth (about the largest array's 1,300 pages in all; measured 1,250), by default each one
    above glibc's adaptive threshold is a fresh mapping and faults in all its pages (the sum,
    ~35,000; measured 29,800). Asserted: by default over 4 times as many faults."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    counts = {}
    for mode in ("reuse", "default"):
        run = subprocess.run([sys.executable, "-c", textwrap.dedent(_FAULTS), mode], env=env, capture_output=True)
        assert run.returncode == 0, run.stderr.decode()
        counts[mode] = int(run.stdout)
    assert 4 * counts["reuse"] < counts["default"]


def test_shape_functions_by_products_interpolate():
    """:func:`elements.evaluate` (powers by products): each shape function is 1 at its own node and
    0 at the other two (to rounding: 1e-15, the coefficients' inverse Vandermonde), and agrees
    with the powers by ``**`` (libm's pow) within 1e-15."""
    from rolling_cli.influence.bem.elements import evaluate, lagrange_coefficients

    nodes = np.array([[-1.0, 0.0, 1.0], [-2.0 / 3.0, 0.0, 2.0 / 3.0], [-1.0, 0.0, 2.0 / 3.0]])
    coefficients = lagrange_coefficients(nodes)
    assert np.abs(evaluate(coefficients, nodes) - np.eye(3)).max() <= 1e-15
    xi = np.random.default_rng(2).uniform(-1.0, 1.0, (3, 50))
    powers = np.matmul(xi[..., None] ** np.arange(3), np.swapaxes(coefficients, -1, -2))
    assert np.abs(evaluate(coefficients, xi) - powers).max() <= 1e-15
