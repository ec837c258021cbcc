"""Exact subsurface stresses of a half-plane under the contact grid's element tractions.

A half-plane z >= 0 (z the depth into the body, x along its surface) carries the
normal traction p_n(x) (<= 0 in compression) and the tangential traction q(x)
on the body along +x, each interpolated on the contact grid's elements exactly
as the solver interpolates them (quadratic or constant, discontinuous). The
Flamant line-load solution (Johnson, Contact Mechanics, 2.15, 2.19) integrated
against a polynomial density over a straight segment is elementary; with the
pressure p = -p_n, zeta = x + i z and the Cauchy integrals

    A(zeta) = int f(s) / (zeta - s) ds,      B(zeta) = int f(s) / (zeta - s)^2 ds = -A'(zeta)

of each density f, the stresses are (compression negative)

    sigma_xx = [ Im A_p - z Re B_p - 2 Re A_q - z Im B_q ] / pi
    sigma_zz = [ Im A_p + z Re B_p + z Im B_q ] / pi
    tau_xz   = [ z Im B_p + Im A_q - z Re B_q ] / pi

so that sigma_zz(x, 0) = p_n(x) and tau_xz(x, 0) = -q(x): tau_xz is the shear
stress in the frame (x, z into the body), the sign of Johnson's equations.

The Cauchy integrals are done in closed form for the interpolated tractions
(:mod:`.cauchy`): exact at every depth, z = 0 included, where they give the
principal values, so that sigma_xx(x, 0) = p_n(x) - (2/pi) pv int q(s)/(x - s) ds.
At a surface point exactly on an element edge where the interpolated traction
jumps, sigma_xx has the logarithmic singularity of that jump and its finite
part (the mean of both sides) is returned.
"""

from __future__ import annotations

import numpy as np

from ..model.grid import ContactGrid, shape_coefficients
from .cauchy import line_integrals


def element_polynomials(grid: ContactGrid, values: np.ndarray) -> np.ndarray:
    """c[e, m] [stress / length^m] with F_e(s) = sum_m c[e, m] (s - m_e)^m on element e (m_e its mid-point).

    ``values`` are the nodal tractions (n,); constant elements give c[:, 1:] = 0.
    """
    ne, k = grid.elements, grid.nodes_per_element
    local = np.asarray(values, dtype=float).reshape(ne, k) @ shape_coefficients(grid.order)  # in xi = 2(s-m)/h
    out = np.zeros((ne, 3))
    out[:, :k] = local * (2.0 / np.diff(grid.edges))[:, None] ** np.arange(k)  # per element: graded grids too
    return out


def cauchy_integrals(
    x: np.ndarray, z: np.ndarray, grid: ContactGrid, densities: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """A [stress] and B [stress/length] (module docstring) of nodal densities (D, n) at points (x, z), z >= 0.

    Complex arrays (P, D); see :func:`rolling_cli.stresses.cauchy.line_integrals`.
    """
    coeff = np.stack([element_polynomials(grid, values) for values in np.atleast_2d(densities)])
    edges = grid.edges - grid.centre
    return line_integrals(np.asarray(x, dtype=float) - grid.centre, z, edges[:-1], edges[1:], coeff)


def stresses_at(
    grid: ContactGrid, p_n: np.ndarray, q: np.ndarray, x: np.ndarray, z: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(sigma_xx, sigma_zz, tau_xz) [stress] at the points (x, z) [length], z >= 0 the depth.

    ``p_n`` the nodal normal tractions (<= 0 in compression), ``q`` the nodal
    tangential tractions on this body along +x [stress]. ``x`` and ``z``
    broadcast together; the outputs have their broadcast shape.
    """
    return both_signs(grid, p_n, q, x, z, (1.0,))[0]


def both_signs(
    grid: ContactGrid, p_n: np.ndarray, q: np.ndarray, x: np.ndarray, z: np.ndarray, signs=(1.0, -1.0)
) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """:func:`stresses_at` for the tangential tractions sign * q, each sign in ``signs``.

    The two bodies of a half-plane pair carry p_t and -p_t with the same p_n:
    the integrals are evaluated once for both.
    """
    x, z = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(z, dtype=float))
    if np.any(z < 0.0):
        raise ValueError("depths z must be >= 0")
    A, B = cauchy_integrals(x.ravel(), z.ravel(), grid, np.stack([-np.asarray(p_n), np.asarray(q)]))
    zz = z.ravel()
    ap, bp = A[:, 0], zz * B[:, 0]
    normal = (ap.imag - bp.real, ap.imag + bp.real, bp.imag)
    aq, bq = A[:, 1], zz * B[:, 1]
    tangential = (-2.0 * aq.real - bq.imag, bq.imag, aq.imag - bq.real)
    return [
        tuple(((n + sign * t) / np.pi).reshape(x.shape) for n, t in zip(normal, tangential, strict=True))
        for sign in signs
    ]


def field(
    grid: ContactGrid, p_n: np.ndarray, q: np.ndarray, x: np.ndarray, z: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(sigma_xx, sigma_zz, tau_xz) [stress] on the tensor grid z (nz,) x x (nx,) [length], shape (nz, nx)."""
    return stresses_at(grid, p_n, q, np.asarray(x)[None, :], np.asarray(z)[:, None])
