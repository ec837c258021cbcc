"""The fast viscoelastic kernels equal the ones they replaced (issue 22 cost targets).

Reference: the kernel code of main cffb703, kept verbatim in ``tests/viscoelastic_reference.py``
(the series by running sums, the Gauss panels one by one, the dense upstream filter, every
wavenumber's phases formed). The fast paths reorder sums and share work, so they agree to
round-off: each tolerance below is a few hundred ulps of the largest entry compared, far above the
measured 1e-16 - 3e-14 and far below anything the solver resolves (its tolerance ~1e-10).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import viscoelastic_reference as old

from rolling_cli.influence import bem
from rolling_cli.influence import viscoelastic as visco
from rolling_cli.influence import viscoelastic_layer as layer
from rolling_cli.model.grid import ContactGrid
from rolling_cli.model.viscoelastic import Viscoelastic

#: Agreement with the old kernels, relative to the largest entry compared: round-off of sums over
#: up to ~2000 wavenumbers or 720 nodes (measured at most 7e-14, on the |b| -> inf Fourier term,
#: whose ~ln(1e12) partial sums cancel to the kernel's size: two digits lost, by either code).
ROUND_OFF = 1e-12


def _relative(new, ref) -> float:
    return float(np.max(np.abs(np.asarray(new) - np.asarray(ref))) / np.max(np.abs(ref)))


def test_phi_and_its_moments_equal_the_old_series():
    """Phi on both sides of its series and asymptotic switches (|a| = 0.5, 40), Psi_j near 0 and
    beyond, and the element moments near and far, for long and short histories of either sign."""
    rng = np.random.default_rng(3)
    a = np.concatenate([rng.uniform(-80.0, 80.0, 3000), rng.uniform(-0.6, 0.6, 600)])
    a = np.concatenate([a, [0.0, 1e-300, -1e-9, 0.4999999, 0.5, -0.5, 40.0, 40.0000001, -41.0]])
    assert _relative(visco.phi(a), old.phi(a)) < ROUND_OFF
    assert np.all(np.abs(visco.phi(a) - old.phi(a)) <= 1e-14 * np.maximum(np.abs(old.phi(a)), 1e-3))
    s = rng.uniform(-3.0, 3.0, 500)
    assert _relative(visco.psi_moments(s), old.psi_moments(s)) < ROUND_OFF
    c = np.concatenate([rng.uniform(-60.0, 60.0, 400), np.linspace(-2.0, 2.0, 13)])
    for beta in (41.3, -0.05, 3.0, -1e4, 0.7):
        assert _relative(visco.phi_moments(c, beta), old.phi_moments(c, beta)) < ROUND_OFF, beta
        assert _relative(visco.exp_moments(c, beta), old.exp_moments(c, beta)) < ROUND_OFF, beta


def test_quadratic_offsets_and_their_memo_across_levels_equal_the_old_kernels():
    """The a-estimate levels of the paper's cover: 29 then 16 elements of the same length (to an ulp),
    the second level's blocks the middle of the first's; then another b/h (a new entry)."""
    visco.clear_memo()
    fine, coarse = ContactGrid(2.806243040080456, 29, 2), ContactGrid(1.5482720221133552, 16, 2)
    assert fine.element_length != coarse.element_length  # one ulp apart: the memo's tolerance
    for grid, b in ((fine, 1.0), (coarse, 1.0), (ContactGrid(1.45, 60, 2), -0.3), (ContactGrid(1.0, 7, 2), 1e-3)):
        new, ref = visco.quadratic_offsets(grid, b, 3.3), old.quadratic_offsets(grid, b, 3.3)
        for got, want in zip(new, ref, strict=True):
            assert got.shape == want.shape
            assert _relative(got, want) < ROUND_OFF, (grid.elements, b)
    visco.clear_memo()
    assert not visco._shape_memo


def test_memoised_elastic_offsets_are_the_half_planes_bit_for_bit():
    """The history's elastic subtrahend from the memo (a finer level's, sliced) is the half-plane's
    log_offsets and sign_offsets exactly: the same integers give the same numbers."""
    from rolling_cli.influence.halfplane import log_offsets, sign_offsets
    from rolling_cli.model.grid import shape_integrals

    visco.clear_memo()
    for grid in (ContactGrid(2.8, 29, 2), ContactGrid(1.5, 16, 2)):
        half = 0.5 * grid.element_length
        log_shape, sign_shape = visco.elastic_shape_offsets(grid.elements)
        log_k = half * (log_shape + np.log(half / 7.0) * shape_integrals(2)[None, None, :])
        assert np.array_equal(log_k, log_offsets(grid, 7.0))
        assert np.array_equal(half * sign_shape, sign_offsets(grid))


@pytest.mark.parametrize("order", [0, 2])
def test_half_plane_body_offsets_equal_the_old_ones(order):
    """The viscoelastic half-plane's blocks (a two-term Prony body, either direction)."""
    visco.clear_memo()
    grid = ContactGrid(1.2, 40, order)
    model = Viscoelastic(young=3.0, compliances=(0.2, 0.1), times=(0.01, 0.3), poisson=0.4, label="Prony")
    for direction in (1, -1):
        new = visco.body_offsets(grid, model, 20.0, direction)
        ref = old.body_offsets(grid, model, 20.0, direction)
        for got, want in zip(new, ref, strict=True):
            assert _relative(got, want) < ROUND_OFF


@pytest.mark.parametrize("b", [1.0, -1.0, 0.01, -3.0, 1e5])
@pytest.mark.parametrize("elements", [5, 60, 130])
def test_banded_upstream_filter_is_the_dense_product(b, elements):
    """F @ X by bands and one carried row against the dense F of :func:`upstream_filter`. The dense F
    loses digits in its far entries (differences of expm1 near -1, ~eps |b| / h of themselves), so the
    tolerance is relative to the product's largest entry (measured at most 5e-14)."""
    x = ContactGrid(1.45, elements, 2).x
    values = np.random.default_rng(elements).standard_normal((x.size, 9))
    dense = layer.upstream_filter(x, b) @ values
    assert _relative(layer.apply_upstream_filter(x, b, values), dense) < ROUND_OFF


@pytest.mark.parametrize(
    ("half_width", "elements", "thickness", "poisson", "b"),
    [(2.806243040080456, 29, 0.1, 0.5, 1.0), (1.45, 120, 0.1, 0.5, 1.0), (3.0, 60, 1.7, 0.49, -0.02),
     (3.0, 80, 0.3, 0.3, 30.0)],
)  # fmt: skip
def test_fourier_offsets_equal_the_old_ones(half_width, elements, thickness, poisson, b):
    """The layer's Fourier remainder with the low wavenumbers by Taylor moments, per block, with the
    |b| -> inf term beside (both on one set of wavenumbers, as the old code)."""
    grid = ContactGrid(half_width, elements, 2)
    lengths = (math.copysign(layer.FAST * 2.0 * half_width, b), b)
    new = layer.fourier_offsets(grid, thickness, poisson, lengths)
    ref = old.fourier_offsets(grid, thickness, poisson, lengths)
    for term in range(2):
        for block in range(3):
            assert _relative(new[term, block], ref[term, block]) < ROUND_OFF, (term, block)


@pytest.mark.parametrize(("speed", "direction", "elements"), [(1.0, -1, 29), (0.05, 1, 40), (30.0, -1, 40)])
def test_cover_compliance_equals_the_old_one(speed, direction, elements):
    """The whole cover on its elastic BEM layer (b = 0.1, 0.2 long elements, nu = 0.5; the paper's
    a-estimate level, and a slower and a faster history), all four blocks."""
    grid = ContactGrid(0.1 * elements, elements, 2)
    thickness = 0.1
    mesh = bem.body_mesh(grid, grid.half_width + 3.0 * thickness, thickness, largest=thickness, far_field=False)
    elastic = bem.condensed(mesh, grid, 20.0, 0.5)
    model = Viscoelastic(young=20.0, compliances=(0.05,), times=(1.0,), poisson=0.5, label="SLS")
    visco.clear_memo()
    new = layer.body_compliance(elastic, grid, model, thickness, speed, direction)
    ref = old.body_compliance(elastic, grid, model, thickness, speed, direction)
    for name in ("S_nn", "S_tt", "S_nt", "S_tn"):
        assert _relative(getattr(new, name), getattr(ref, name)) < ROUND_OFF, name


def test_normal_only_cover_is_the_full_normal_block_and_the_relaxed_rest():
    """The a-estimate levels' cover (the history on S_nn alone, ``normal_only``): S_nn is the full
    compliance's to round-off (the same sums over a third of the Fourier columns; ROUND_OFF of its
    largest entry), the other three blocks the relaxed layer's, J_r E_g times the BEM's, exactly."""
    grid = ContactGrid(2.9, 29, 2)
    thickness = 0.1
    mesh = bem.body_mesh(grid, grid.half_width + 3.0 * thickness, thickness, largest=thickness, far_field=False)
    elastic = bem.condensed(mesh, grid, 20.0, 0.5)
    model = Viscoelastic(young=20.0, compliances=(0.05,), times=(1.0,), poisson=0.5, label="SLS")
    full = layer.body_compliance(elastic, grid, model, thickness, 1.0, -1)
    normal = layer.body_compliance(elastic, grid, model, thickness, 1.0, -1, normal_only=True)
    assert _relative(normal.S_nn, full.S_nn) < ROUND_OFF
    factor = model.relaxed / model.glassy
    for name in ("S_tt", "S_nt", "S_tn"):
        assert np.array_equal(getattr(normal, name), factor * getattr(elastic, name)), name
        assert not np.allclose(getattr(full, name), getattr(normal, name)), name  # the history is there


def test_a_repeating_a_estimate_level_is_skipped(monkeypatch):
    """The paper's cover (the bench's Fig. 11 tyre as an SLS cover): its first a-estimate level (29
    elements of 0.1935, set by the layer) measures a more than two spacings from the guess; the next
    level (16 elements of the same length to an ulp, also set by the layer) measures the same width:
    it is skipped, one level instead of two, the same a (1e-12: the two levels' cell extents differ
    by round-off). The shipped cover's first level has 16 elements of 1.0 (set by the guess, not by
    its 5 mm layer): its second level, 2.5x finer, still runs (and measures 2.97 against 3.07)."""
    import tomllib
    from pathlib import Path

    from rolling_cli.case import load_case
    from rolling_cli.pipeline import mesh_path

    cases = Path(__file__).resolve().parents[1] / "cases"
    with open(cases / "tyred_fig11_q41.toml", "rb") as handle:
        data = tomllib.load(handle)
    data["bodies"]["B"].update(viscoelastic=True, young=20.0, relaxed_young=10.0, creep_time=1.0)
    data["rolling"]["speed"] = 1.0
    with open(cases / "rubber_cover.toml", "rb") as handle:
        shipped = tomllib.load(handle)

    def estimate(case):
        path = mesh_path.MeshPath(case, mesh_path.plan(case), estimates_only=True)
        path.run()
        return len(path.levels), path.measured_half_width

    for case_data, levels in ((data, (1, 2)), (shipped, (2, 2))):
        case = load_case(case_data)
        skipped = estimate(case)
        with monkeypatch.context() as patch:
            patch.setattr(mesh_path, "repeats_estimate", lambda *args: False)
            both = estimate(case)
        assert (skipped[0], both[0]) == levels
        assert skipped[1] == pytest.approx(both[1], rel=1e-12)


@pytest.mark.parametrize("n", [2, 40, 480])
def test_small_wavenumber_spectrum_is_the_direct_sum(n):
    """The hysteresis output's low wavenumbers by the exponential's series (k max x <= 1) against the
    direct sums of cosines and sines it replaced, on the geometric panels of
    :func:`~rolling_cli.references.hysteresis._spectrum`: both err by ~eps sum |p| (the tolerance
    1e-13 of it; measured ~1e-16)."""
    from rolling_cli.references import hysteresis

    h = 2.0 / n
    x = np.arange(n) * h
    p = np.random.default_rng(n).standard_normal((n, 2))
    k = 2.0 * np.pi / (n * h) * 0.5 ** np.arange(0.0, 30.0, 0.37)
    phase = np.outer(k, x)
    direct = np.cos(phase) @ p - 1j * (np.sin(phase) @ p)
    assert np.max(np.abs(hysteresis._small_spectrum(k, x, p) - direct)) < 1e-13 * np.sum(np.abs(p))
