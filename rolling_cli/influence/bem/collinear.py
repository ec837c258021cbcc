"""Element integrals for a collocation point on the element's own straight line, in closed form.

When the point x_i lies on the line of a straight element (its own element,
and every element of the same straight side of the boundary: the contact zone
and the whole top face, where most pairs are), r = x(xi) - x_i is parallel to
the element's unit tangent t, so r_k = sgn(xi - c) t_k, r = J |xi - c| and
dr/dn = 0, with c the point's local coordinate on the line and J the
half-length. Kelvin's kernels (:mod:`.kelvin`) then reduce to

    int U_kl N_j J d xi = C_U J [ (3 - 4 nu) (-ln J mu_j - lambda_j(c)) delta_kl + mu_j t_k t_l ]
    int T_kl N_j J d xi = (1 - 2 nu) / (4 pi (1 - nu)) (t_k n_l - t_l n_k) kappa_j(c)

with C_U = 1/(8 pi G (1 - nu)), mu_j = int N_j, lambda_j = int N_j ln|xi - c|
and kappa_j = int N_j / (xi - c), all over xi in [-1, 1]: combinations of the
moments L_m and K_m of xi^m (:func:`line_moments`), in closed form near the element, by Gauss-Legendre
on the smooth integrand a little further, and by their series in 1/c far
away, where the closed forms cancel.

For the element's own node j = a (c at that node) the strongly singular term
is left out (zero): the diagonal blocks of H come from the rigid-body
condition; for its other nodes N_j(c) = 0 and kappa_j = 2 (A_1 + A_2 c) exactly.
"""

from __future__ import annotations

import numpy as np

from ...model.kernels import log_moments

#: Up to |c| = NEAR_LINE the moments are in closed form, up to SERIES by Gauss-Legendre on the
#: smooth integrand, beyond by their series in 1/c, of which the terms up to z^(2 PAIRS - 1) are
#: kept (the first one left out is below SERIES^-(2 PAIRS) = 1e-18 of the leading term).
NEAR_LINE = 2.0
SERIES = 8.0
PAIRS = 10
_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(12)
_MOMENTS = np.array([2.0, 0.0, 2.0 / 3.0])  # M_m = int xi^m over [-1, 1]


def _series_tables() -> np.ndarray:
    """(6, PAIRS): row m the coefficients of sum_{s>=1} M_{m+s} z^s / s, row 3 + m those of
    sum_{s>=0} M_{m+s} z^s, in powers z^(2u + m % 2) (M_p vanishes for odd p)."""
    table = np.zeros((6, PAIRS))
    for m in range(3):
        for u in range(PAIRS):
            s = 2 * u + m % 2
            moment = 2.0 / (m + s + 1.0)
            table[m, u] = moment / s if s else 0.0
            table[3 + m, u] = moment
    return table


_SERIES_TABLE = _series_tables()
_ODD = np.array([0, 1, 0, 0, 1, 0], dtype=bool)


def far_moments(c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """L_m and K_m (see :func:`line_moments`) by their series
    in z = 1/c, for |c| >= ``SERIES``: (P,) -> two (P, 3).

    L_m = ln|c| M_m - sum_{s>=1} M_{m+s} z^s / s, K_m = -sum_{s>=0} M_{m+s} z^(s+1),
    with M_p = int xi^p; evaluated by Horner in z^2.
    """
    z = 1.0 / c[:, None]
    w = z * z
    out = np.zeros((c.size, 6))
    for u in range(PAIRS - 1, -1, -1):
        out *= w
        out += _SERIES_TABLE[:, u]
    out[:, _ODD] *= z
    log_part = np.log(np.abs(c))[:, None] * _MOMENTS - out[:, :3]
    return log_part, -z * out[:, 3:]


def line_moments(c: np.ndarray, on_element: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """L_m(c) = int xi^m ln|xi - c| and K_m(c) = int xi^m / (xi - c) over xi in [-1, 1], m = 0, 1, 2.

    ``c`` (P,); returns two (P, 3) arrays (dimensionless). K is left zero where
    ``on_element`` (|c| <= 1, not needed there). L: :func:`rolling_cli.model.kernels.log_moments`
    up to |c| = ``SERIES``. K: closed form up to ``NEAR_LINE`` (K_0 =
    ln|(1 - c)/(1 + c)|, K_1 = 2 + c K_0, K_2 = c K_1), 12-point Gauss-Legendre
    up to ``SERIES`` (the pole outside the Bernstein ellipse of parameter
    2 + sqrt(3): relative error < 2e-14). Beyond, both by :func:`far_moments`.
    """
    c = np.asarray(c, dtype=float)
    L = np.empty(c.shape + (3,))
    K = np.zeros(c.shape + (3,))
    size = np.abs(c)
    far = size > SERIES
    L[far], K[far] = far_moments(c[far])
    L[~far] = log_moments(c[~far])
    near = ~on_element & (size <= NEAR_LINE)
    cn = c[near]
    k0 = np.log((cn - 1.0) / (cn + 1.0))
    K[near, 0] = k0
    K[near, 1] = 2.0 + cn * k0
    K[near, 2] = cn * K[near, 1]
    middle = ~far & (size > NEAR_LINE)
    values = _GAUSS_W / (_GAUSS_X[None, :] - c[middle][:, None])  # (P, 12)
    K[middle] = values @ (_GAUSS_X[:, None] ** np.arange(3)[None, :])
    return L, K


def integrals(
    c: np.ndarray,
    own: np.ndarray,
    coeff: np.ndarray,
    half: np.ndarray,
    tangent: np.ndarray,
    shear: float,
    poisson: float,
    out: tuple[np.ndarray, np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """H and G integrals of e elements on one line against n points on it, each (e, 3, 2, n, 2).

    ``c`` (e, n) each point's local coordinate on each element's line (exactly
    the node's local coordinate for the element's own nodes); ``own`` (e, n)
    the point's position among the element's nodes, -1 when it is not one of
    them; per element ``coeff`` (e, 3, 3) the shape-function coefficients,
    ``half`` (e,) the half-length J [length] and ``tangent`` (e, 2) the unit
    tangent; ``shear`` G [stress]. Layout [element, node j, l, point, k] (that
    of :func:`.assembly.element_blocks`); H is dimensionless, G in
    [length/stress] times length. ``out``: two arrays of that shape to write
    them into (returned).
    """
    member = own >= 0
    if np.any(~member & (np.abs(np.abs(c) - 1.0) < 1e-9)):
        raise ValueError("a collocation point sits on the end of an element it does not belong to")
    L, K = line_moments(c.ravel(), member.ravel())
    lam = np.einsum("ejm,enm->ejn", coeff, L.reshape(c.shape + (3,)))  # (e, 3, n)
    kappa = np.einsum("ejm,enm->ejn", coeff, K.reshape(c.shape + (3,)))
    # on the element (its own nodes) N_j(c) = delta_ja: kappa_j is the polynomial part 2 (A_1 + A_2 c)
    e, n = np.nonzero(member)
    kappa[e, :, n] = 2.0 * (coeff[e, :, 1] + coeff[e, :, 2] * c[e, n, None])
    kappa[e, own[e, n], n] = 0.0  # the own node's term: the rigid-body diagonal
    # G = A delta_kl + B t_k t_l; H = kappa (t_k n_l - t_l n_k) with n = (t_y, -t_x): -kappa at (k, l) = (0, 1)
    cu = 1.0 / (8.0 * np.pi * shear * (1.0 - poisson))
    mu = coeff @ _MOMENTS  # (e, 3)
    scale = (cu * half)[:, None, None]
    isotropic = scale * (3.0 - 4.0 * poisson) * ((-np.log(half)[:, None] * mu)[:, :, None] - lam)  # (e, 3, n)
    along = scale * mu[:, :, None]  # (e, 3, 1)
    h, g = out if out is not None else (np.empty(kappa.shape[:2] + (2,) + kappa.shape[2:] + (2,)) for _ in range(2))
    g[:, :, 0, :, 0] = isotropic + along * (tangent[:, 0] ** 2)[:, None, None]
    g[:, :, 1, :, 1] = isotropic + along * (tangent[:, 1] ** 2)[:, None, None]
    g[:, :, 0, :, 1] = along * (tangent[:, 0] * tangent[:, 1])[:, None, None]
    g[:, :, 1, :, 0] = g[:, :, 0, :, 1]
    kappa *= (1.0 - 2.0 * poisson) / (4.0 * np.pi * (1.0 - poisson))
    h[:, :, 0, :, 0] = 0.0
    h[:, :, 1, :, 1] = 0.0
    h[:, :, 1, :, 0] = -kappa  # l = 1, k = 0
    h[:, :, 0, :, 1] = kappa
    return h, g
