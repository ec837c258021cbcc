"""A finite cover bonded to an elastic core (issue 21 item 1): the two-region BEM of
:mod:`rolling_cli.influence.bem.core` against Michell's two-region series
(:mod:`rolling_cli.references.annulus_core`), the rigid-core and homogeneous limits, and the
case keys (core_young, core_poisson, inner_radius)."""

import numpy as np
import pytest

from rolling_cli.influence.bem import core, cylinder
from rolling_cli.model.grid import ContactGrid
from rolling_cli.references import annulus, annulus_core

E, NU = 2.0e5, 0.3
R, RC, RI = 20.0, 16.0, 1.0  # a cover b = 4 = 4 a on a core, bore 0.05 R
GRID = ContactGrid(1.5, 30, 2)  # a = 1: a/R = 0.05


def _bump(s, a=1.0):
    """A smooth unit load (1 - s^2/a^2)^2 on |s| < a (C1: the BEM's quadratic interpolation of it
    is within ~(h/a)^3, so the comparison measures the body model; as tests/test_cylinder_bem.py)."""
    return np.where(np.abs(s) < a, (1.0 - (s / a) ** 2) ** 2, 0.0)


def _largest(c):
    return max(np.abs(getattr(c, n)).max() for n in ("S_nn", "S_nt", "S_tn", "S_tt"))


def _difference(c, d):
    return max(np.abs(getattr(c, n) - getattr(d, n)).max() for n in ("S_nn", "S_nt", "S_tn", "S_tt"))


def test_michell_core_limits():
    """The reference's own limits. (1) A core of the cover's material is the single annulus
    r_i < r < R (:mod:`.annulus`): the same functions, only differently normalised, so round-off
    (bound 1e-12 of the largest response). (2) A core 1e6 times stiffer is the rigid core of
    the annulus r_c < r < R: the core's own compliance is G / G_c = 1e-6 of the cover's times a
    geometry factor, largest for the torsion (u_theta = D / r in each region): the core's
    1/r_i^2 - 1/r_c^2 over the cover's 1/r_c^2 - 1/R^2 (~710 here); bound twice their product."""
    modes = 4096
    bound = 2.0 * 1e-6 * (1.0 / RI**2 - 1.0 / RC**2) / (1.0 / RC**2 - 1.0 / R**2)
    same = annulus_core.mode_responses(modes, RI / R, RC / R, NU, NU, 1.0)
    single = annulus.mode_responses(modes, RI / R, NU)
    assert np.abs(same - single).max() <= 1e-12 * np.abs(single).max()
    assert np.allclose(annulus_core.axisymmetric(RI / R, RC / R, NU, NU, 1.0), annulus._axisymmetric(RI / R, NU))
    stiff = annulus_core.mode_responses(modes, RI / R, RC / R, NU, 0.25, 1e6)
    rigid = annulus.mode_responses(modes, RC / R, NU)
    assert np.abs(stiff - rigid).max() <= bound * np.abs(rigid).max()
    a0, b0 = annulus_core.axisymmetric(RI / R, RC / R, NU, 0.25, 1e6)
    a1, b1 = annulus._axisymmetric(RC / R, NU)
    assert abs(a0 - a1) <= bound * a1 and abs(b0 - b1) <= bound * b1


def _michell(radius, core_radius, inner, young_core, poisson_core, sigma_rr, sigma_rt, samples=2**18):
    """Michell's two-region w (into the body) and u_t at the contact nodes for tractions given as
    functions of the arc length s (as tests/test_cylinder_bem.py)."""
    theta = 2.0 * np.pi * np.arange(samples) / samples
    theta = np.where(theta > np.pi, theta - 2.0 * np.pi, theta)
    s = radius * theta
    u_r, u_t = annulus_core.surface_displacement(
        sigma_rr(s),
        sigma_rt(s),
        radius,
        core_radius,
        inner,
        E / (2.0 * (1.0 + NU)),
        NU,
        young_core / (2.0 * (1.0 + poisson_core)),
        poisson_core,
    )
    order = np.argsort(theta)
    angles = GRID.x / radius
    return np.interp(angles, theta[order], -u_r[order]), np.interp(angles, theta[order], u_t[order])


@pytest.mark.parametrize(("core_young", "core_poisson"), [(0.2 * E, 0.25), (5.0 * E, 0.35)])
def test_bem_core_matches_michell(core_young, core_poisson):
    """The cover on a softer and on a stiffer core, at a/R = 0.05, against Michell's two-region
    series: the contact nodes' displacements under a normal and a tangential unit bump within
    0.5 % of the largest (the brief's bound; the one-region BEM meets Michell within 6e-6 in
    tests/test_cylinder_bem.py, the interface adds the core's BEM of the same element sizes;
    measured 7e-5 at most)."""
    c = core.condensed(GRID, R, RC, RI, E, NU, core_young, core_poisson)
    load = -_bump(GRID.x)
    zero = np.zeros_like(load)
    for p_n, p_t in ((load, zero), (zero, load)):
        w = c.S_nn @ p_n + c.S_nt @ p_t
        u_t = c.S_tn @ p_n + c.S_tt @ p_t
        sigma_rr = (lambda s: -_bump(s)) if p_n is load else (lambda s: 0.0 * s)
        sigma_rt = (lambda s: -_bump(s)) if p_t is load else (lambda s: 0.0 * s)
        w_ref, u_ref = _michell(R, RC, RI, core_young, core_poisson, sigma_rr, sigma_rt)
        scale = max(np.abs(w_ref).max(), np.abs(u_ref).max())
        assert np.abs(w - w_ref).max() <= 5e-3 * scale
        assert np.abs(u_t - u_ref).max() <= 5e-3 * scale
