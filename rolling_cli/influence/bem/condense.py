"""Condensation of a BEM body onto its contact nodes (the paper's eq. 13).

The body's boundary values are known everywhere except the unknowns of the
square system A X = B y (u where the traction is known, t where u is known).
A load case is the contact tractions t_c (zero traction elsewhere on the top
face) plus, on a half-space's truncation boundary, the far-field displacement
of their resultant F = sum_j w_j t_j (:mod:`.farfield`):

    y = E_c t_c + V F,   F = W t_c,

with E_c the injection of the contact dofs, V the far-field values per unit
force (2N, 2) and W (2, 2 n_c) the resultant weights. The contact
displacements are then linear in t_c, and all 2 n_c unit load cases plus the
2 far-field ones share one LU factorisation of A (many right-hand sides):

    C = (A^-1 B E_c)_c + (A^-1 B V)_c W.

:mod:`.system` assembles A and R = [B E_c | B V] directly, column-major, with
the contact unknowns first, for each reduction of :mod:`.symmetry` (the whole
system, or the two mirror halves of a symmetric body); here each A is
factorised in place (LAPACK getrf), its right-hand sides are solved in place
(getrs), and the first rows of the solutions give C. One LU per reduction, no
copies of A.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ... import blas
from .mesh import BoundaryMesh
from .symmetry import Reduction

#: Rows of a compliance block updated at once by the far field's rank-one terms (bounds a temporary).
_ROWS = 256


def boundary_system(mesh: BoundaryMesh, H: np.ndarray, G: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The dense square system A X = B y from H and G, in node order: X the unknown
    boundary values (u where the traction is known, t where u is known), y the
    known values; returns (A, B). (The model itself assembles A straight from
    the element integrals, :mod:`.system`; this form serves checks.)"""
    fixed = np.repeat(mesh.fixed, 2)
    A = np.where(fixed[None, :], -G, H)
    B = np.where(fixed[None, :], -H, G)
    return A, B


def factorise(matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """LU of a column-major float64 matrix, in place (its storage becomes the factors): (lu, pivots)."""
    from scipy.linalg import lapack  # lazy: its import costs ~0.2 s of CPU, which small bodies skip (solve_small)

    blas.settle()  # scipy's BLAS, perhaps loaded just now, on the command's threads
    lu, pivots, info = lapack.dgetrf(matrix, overwrite_a=True)
    if info > 0:
        raise np.linalg.LinAlgError("the BEM boundary system is singular")
    return lu, pivots


def solve(factors: tuple[np.ndarray, np.ndarray], rhs: np.ndarray, overwrite: bool = False) -> np.ndarray:
    """A^-1 rhs for the factors of :func:`factorise`; ``overwrite`` solves in the (column-major) rhs."""
    from scipy.linalg import lapack

    blas.settle()
    x, info = lapack.dgetrs(*factors, rhs, overwrite_b=overwrite)
    if info != 0:
        raise ValueError(f"getrs: illegal argument {-info}")
    return x


#: Unknowns up to which :func:`solve_small` solves with numpy (a copy of A, at most 18 MB).
SMALL_SYSTEM = 1500


def solve_small(matrix: np.ndarray, rhs: np.ndarray) -> np.ndarray | None:
    """A^-1 rhs by numpy's LAPACK (gesv: the same LU with partial pivoting as :func:`factorise` and
    :func:`solve`, on copies) for a system of at most ``SMALL_SYSTEM`` unknowns, else None. It
    spares a small body's whole process the import of scipy.linalg (~0.2 s of CPU, more than numpy's
    own), where the copies cost little; larger systems take the in-place path."""
    if matrix.shape[0] > SMALL_SYSTEM:
        return None
    try:
        return np.linalg.solve(matrix, rhs)
    except np.linalg.LinAlgError as error:
        raise np.linalg.LinAlgError("the BEM boundary system is singular") from error


#: Unknowns from which :func:`solve_all` solves two systems at once (each LU then takes ~15 ms or more).
PARALLEL_SYSTEM = 400


def solve_all(systems: list) -> list[np.ndarray]:
    """A^-1 R of each :class:`.system.MixedSystem` in ``systems`` (the list is emptied, each system
    released once solved): by :func:`solve_small` where small enough, else in place
    (:func:`factorise`, :func:`solve`).

    Two systems (a mirror-symmetric body's halves) of at least ``PARALLEL_SYSTEM`` unknowns each,
    in a process allowed two CPUs or more, are solved at once, the second in a thread of its own:
    LAPACK runs outside the GIL, and each call is the same call as in turn, on its own arrays
    (with one BLAS thread, the command's default, the same numbers bit for bit). The finite
    roller of benchmarks/finite_roller.py: two systems of 766 unknowns and 601 right-hand sides,
    ~60 ms each on one core."""
    if len(systems) == 2 and min(system.matrix.shape[0] for system in systems) >= PARALLEL_SYSTEM and _cpus() > 1:
        import threading

        out: list = [None, None]
        errors: list = []

        def run(index: int) -> None:
            try:
                out[index] = _solve_one(systems[index])
            except BaseException as error:  # noqa: BLE001 - re-raised in the caller's thread below
                errors.append(error)

        second = threading.Thread(target=run, args=(1,), name="bem-half")
        second.start()
        run(0)
        second.join()
        systems.clear()
        if errors:
            raise errors[0]
        return out
    solutions = []
    while systems:
        solutions.append(_solve_one(systems.pop(0)))
    return solutions


def _solve_one(system) -> np.ndarray:
    """A^-1 R of one system: numpy's gesv when small, else the in-place LU (overwrites A and R)."""
    small = solve_small(system.matrix, system.rhs)  # numpy's LAPACK: no scipy import (start-up)
    return small if small is not None else solve(factorise(system.matrix), system.rhs, overwrite=True)


def _cpus() -> int:
    """The CPUs this process may run on."""
    import os

    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def contact_blocks(
    solutions: list[np.ndarray], parts: list[Reduction], mesh: BoundaryMesh, weights: np.ndarray
) -> dict[str, np.ndarray]:
    """The body's compliance blocks from the solved right-hand sides [length/stress], each (n_c, n_c).

    ``solutions[r]`` = A^-1 R of reduction ``parts[r]`` (:mod:`.system`):
    rows its unknowns (contact displacement parameters first), columns its
    contact parameters' unit loads, then its far-field forces; ``weights``
    (n_c,) [length] the contact quadrature weights (F = sum_j w_j t_j). The
    far field's terms are added into the solutions (in place). In the body's
    frame the displacement into the body is -u_y, p_n = t_y and p_t = t_x:
    S_tt = du_x/dt_x, S_tn = du_x/dt_y, S_nt = -du_y/dt_x, S_nn = -du_y/dt_y.
    C-contiguous arrays.
    """
    contact = mesh.contact
    nc = contact.size
    responses = []
    for solution, part in zip(solutions, parts, strict=True):
        m = part.contact
        response = solution[:m, :m]
        for column, axis in enumerate(part.forces):  # + (du/dF) F of each parameter's unit load
            valid = part.unknown[contact, axis] >= 0
            loaded = contact[valid]
            load = weights[valid] * part.sign[loaded, axis]
            resultant = np.bincount(part.unknown[loaded, axis], weights=load, minlength=m)
            far = solution[:m, m + column]
            if not far.any():  # no far field (a finite body's shaft is its reference): nothing to add
                continue
            for start in range(0, m, _ROWS):
                response[:, start : start + _ROWS] += np.outer(far, resultant[start : start + _ROWS])
        responses.append(response)
    out = {}
    for name, k, l, sign in (("S_tt", 0, 0, 1.0), ("S_tn", 0, 1, 1.0), ("S_nt", 1, 0, -1.0), ("S_nn", 1, 1, -1.0)):
        block = np.zeros((nc, nc))
        for response, part in zip(responses, parts, strict=True):
            rows = np.maximum(part.unknown[contact, k], 0)  # the factor is 0 where a half has no parameter
            cols = np.maximum(part.unknown[contact, l], 0)
            row_factor = sign * part.sign[contact, k]
            col_factor = part.weight[contact, l]
            col_runs = runs(cols)
            for start in range(0, nc, _ROWS):  # in row chunks: bounded temporaries
                part_rows = slice(start, start + _ROWS)
                gathered = _gather(response, rows[part_rows], cols, col_runs)
                gathered *= row_factor[part_rows, None]
                gathered *= col_factor[None, :]
                block[part_rows] += gathered
        out[name] = block
    return out


#: Index runs beyond which :func:`_gather` indexes element by element (np.ix_) instead of by slices.
_MAX_RUNS = 16


def _gather(matrix: np.ndarray, rows: np.ndarray, cols: np.ndarray, col_runs: list) -> np.ndarray:
    """matrix[np.ix_(rows, cols)] (a new array, the same numbers), copied through strided views
    where the indices are a few runs of step +-1 (a mirror half's contact parameters: one run
    each way), ~4 times faster than fancy indexing; ``col_runs`` = :func:`runs` (cols)."""
    row_runs = runs(rows)
    if len(row_runs) * len(col_runs) > _MAX_RUNS:
        return matrix[np.ix_(rows, cols)]
    out = np.empty((rows.size, cols.size))
    for target_rows, source_rows in row_runs:
        for target_cols, source_cols in col_runs:
            out[target_rows, target_cols] = matrix[source_rows, source_cols]
    return out


def runs(index: np.ndarray) -> list[tuple[slice, slice]]:
    """(target, source) slice pairs covering the integer ``index`` array (n,): target the run's
    positions in ``index``, source its values, for maximal stretches of steps all +1 or all -1
    (a lone value is a run of its own)."""
    step = np.diff(index)
    cuts = np.flatnonzero((np.abs(step) != 1) | np.concatenate([[False], step[1:] != step[:-1]])) + 1
    bounds = [0, *cuts.tolist(), index.size]
    out = []
    for lo, hi in zip(bounds[:-1], bounds[1:], strict=True):
        if hi <= lo:
            continue
        by = int(step[lo]) if hi - lo > 1 else 1
        first, stop = int(index[lo]), int(index[hi - 1]) + by
        out.append((slice(lo, hi), slice(first, stop if stop >= 0 else None, by)))
    return out


@dataclass(frozen=True)
class Condensed:
    """A factorised BEM body, ready for load cases (plain arrays, read-only use).

    Per reduction (``parts``, :mod:`.symmetry`): ``factors`` the LU of its A and
    ``rhs`` its R = [B E_c | B V]; ``far_values`` = V (2N, 2) [length /
    (force/length)]; ``weights`` (n_c,) the contact quadrature weights [length].
    """

    mesh: BoundaryMesh
    parts: list
    factors: list
    rhs: list
    far_values: np.ndarray
    weights: np.ndarray


def prepare(mesh: BoundaryMesh, parts: list, systems: list, weights: np.ndarray, far_values: np.ndarray) -> Condensed:
    """Factorise the ``systems`` of the reductions ``parts`` (in place: each matrix becomes its LU)."""
    factors = [factorise(system.matrix) for system in systems]
    return Condensed(mesh, parts, factors, [system.rhs for system in systems], far_values, weights)


def boundary_values(body: Condensed, tractions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every boundary node's displacement and traction for contact nodal tractions.

    ``tractions`` (n_c, 2) [stress]: (t_x, t_y) at the contact nodes in
    increasing x. Returns u (N, 2) [length] and t (N, 2) [stress] at the
    mesh nodes, far-field conditions included.
    """
    t_c = np.asarray(tractions, dtype=float)
    mesh = body.mesh
    contact = mesh.contact
    force = body.weights @ t_c  # (F_x, F_y)
    unknown = np.zeros((mesh.size, 2))  # u where the traction is known, t where u is
    for part, factors, rhs in zip(body.parts, body.factors, body.rhs, strict=True):
        valid = part.unknown[contact] >= 0
        weighted = (part.weight[contact] * t_c)[valid]
        loads = np.bincount(part.unknown[contact][valid], weights=weighted, minlength=part.contact)
        solution = solve(factors, rhs @ np.concatenate([loads, force[list(part.forces)]]))
        kept = part.unknown >= 0
        unknown[kept] += part.sign[kept] * solution[part.unknown[kept]]
    known = body.far_values.reshape(mesh.size, 2, 2) @ force  # (N, 2): the far field, zero elsewhere
    known[contact] = t_c
    fixed = mesh.fixed[:, None]
    return np.where(fixed, known, unknown), np.where(fixed, unknown, known)
