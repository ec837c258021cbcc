"""Stress invariants and fatigue indicators of a plane-strain field (pure functions).

Inputs are the in-plane components sigma_xx, sigma_zz, tau_xz [stress] (any
shape) and Poisson's ratio; the out-of-plane stress of plane strain is
sigma_yy = nu (sigma_xx + sigma_zz). Compression is negative.
"""

from __future__ import annotations

import numpy as np


def out_of_plane(sigma_xx: np.ndarray, sigma_zz: np.ndarray, poisson: float) -> np.ndarray:
    """sigma_yy [stress] of plane strain (epsilon_yy = 0)."""
    return poisson * (sigma_xx + sigma_zz)


def principal(sigma_xx: np.ndarray, sigma_zz: np.ndarray, tau_xz: np.ndarray, poisson: float) -> np.ndarray:
    """Principal stresses sigma_1 >= sigma_2 >= sigma_3 [stress], stacked on a new first axis (3, ...).

    The in-plane pair is c +- R (Mohr's circle, c the mean, R the radius); the
    third is sigma_yy.
    """
    centre = 0.5 * (sigma_xx + sigma_zz)
    radius = np.hypot(0.5 * (sigma_xx - sigma_zz), tau_xz)
    return np.sort(np.stack([centre + radius, centre - radius, out_of_plane(sigma_xx, sigma_zz, poisson)]), axis=0)[
        ::-1
    ]


def von_mises(sigma_xx: np.ndarray, sigma_zz: np.ndarray, tau_xz: np.ndarray, poisson: float) -> np.ndarray:
    """Von Mises equivalent stress sqrt(3 J2) [stress]."""
    sigma_yy = out_of_plane(sigma_xx, sigma_zz, poisson)
    normal = (sigma_xx - sigma_yy) ** 2 + (sigma_yy - sigma_zz) ** 2 + (sigma_zz - sigma_xx) ** 2
    return np.sqrt(0.5 * normal + 3.0 * tau_xz**2)


def tresca(stresses: np.ndarray) -> np.ndarray:
    """Tresca stress sigma_1 - sigma_3 [stress] from :func:`principal`'s output (twice the maximum shear)."""
    return stresses[0] - stresses[-1]


def orthogonal_shear_range(tau_xz: np.ndarray) -> np.ndarray:
    """Range of tau_xz over a rolling pass at each depth: max - min along x [stress].

    ``tau_xz`` has shape (nz, nx); the result (nz,). Every material point at
    depth z passes through all x during one pass, so this is the amplitude of
    the orthogonal shear that drives subsurface fatigue at that depth.
    """
    return tau_xz.max(axis=1) - tau_xz.min(axis=1)
