"""Rolling resistance of a solved viscoelastic case: moments, coefficient, pressure shift, hysteresis.

Frame and signs (README "Units and conventions"): x along the rolling
direction, the cylinders' centres on x = 0, p_n <= 0, p_t the traction on A,
V = sgn(V) |V| the velocity of the material through the contact. Per unit
axial length:

* moment of the contact tractions about A's shaft, taken positive when it
  opposes A's rotation: M_A = sgn(V) (sum w p_n x - R_A Q); about B's shaft
  M_B = sgn(V) (sum w p_n x + R_B Q) (NaN for a flat body, whose shaft is at
  infinity);
* the pair's rolling-resistance moment M = sgn(V) sum w p_n x
  (= R* (M_A/R_A + M_B/R_B): the shafts' power at the common speed |V| is
  |V| M / R*) and the coefficient M / (P R*), which for a cylinder on a flat
  without friction is Hunter's x_c / R;
* the pressure centroid x_c = sum w (-p_n) x / P (moves towards the leading
  edge, x_c sgn(V) < 0) and the shift towards the leading edge,
  -sgn(V) x_c;
* the hysteresis power in the bodies per unit |V|, from the loss compliance
  (:mod:`rolling_cli.references.hysteresis`, an independent route; quadratic
  elements enter as cell averages, :func:`quadratic_cells`); a viscoelastic
  layer adds its loss beyond the half-plane's
  (:func:`rolling_cli.references.layer_fourier.remainder_power`); a viscoelastic finite
  cylinder's is its annulus's, mode by mode round the circle
  (:func:`rolling_cli.references.annulus.hysteresis_power`).

In steady state the shafts' power balances the losses: |V| M / R* =
hysteresis + frictional power + xi Q |V| (the last the power of the speed
difference V_A - V_B = xi |V| through Q). For a finite roller on a rigid flat
the pressure is radial (no moment about the shaft) and that balance needs
the tractions' displaced points: the rolling-resistance force F_rr of
:mod:`.power_balance` (``rolling_resistance_force``; the coefficient is then
F_rr / P, M / (P R) in the half-space limit).
"""

from __future__ import annotations

import math

import numpy as np

from ..references import annulus, hysteresis, layer_fourier
from . import power_balance, viscoelastic

#: Cells per quadratic element for the hysteresis (the Fourier formula takes piecewise-constant
#: tractions): the cell averages of the element's quadratic. The step approximation adds a loss of
#: order ell sum(jumps^2) ln(1/(k ell)) from its jumps of ~ (h / cells) p'; at 12 cells the energy
#: balance closes to 1e-4 (tests/test_viscoelastic.py).
QUADRATIC_CELLS = 12


def quadratic_cells(p: np.ndarray) -> np.ndarray:
    """Cell averages [stress] of the piecewise-quadratic traction with nodal values ``p`` (3 per
    element, local coordinates -2/3, 0, 2/3) on :data:`QUADRATIC_CELLS` equal cells per element."""
    from .grid import shape_coefficients

    edges = np.linspace(-1.0, 1.0, QUADRATIC_CELLS + 1)
    powers = np.arange(3)
    antiderivative = edges[:, None] ** (powers + 1) / (powers + 1)  # int_0^xi xi^m
    means = np.diff(antiderivative, axis=0) / np.diff(edges)[:, None]  # (cells, m)
    averages = means @ shape_coefficients(2).T  # (cells, k): mean of N_k over each cell
    return (np.asarray(p, dtype=float).reshape(-1, 3) @ averages.T).reshape(-1)


def attributes(case, system, p_n: np.ndarray, p_t: np.ndarray, radius: float, surface=None) -> dict:
    """The rolling-resistance quantities of a solved viscoelastic case (declared in
    :mod:`rolling_cli.result.quantities`); ``radius`` R* [length], ``system`` its
    :class:`~rolling_cli.solver.system.ContactSystem` (node positions, weights, spacing);
    ``surface`` (w, u) [length], finite body A's surface displacements against a rigid flat
    (:func:`finite_on_flat`) on a uniform grid (the balance's element rule reads one element
    length), or None."""
    x, w = system.x, system.weights
    d = float(case.rolling.direction)
    load = float(-(w @ p_n))
    normal = system.load(p_n, p_t)  # P as normal.load prescribes it (a finite cylinder's: on its shaft)
    q = float(w @ p_t)
    first = float(w @ (p_n * x))
    centroid = -first / load if load > 0.0 else math.nan
    moment = d * first
    r_a, r_b = float(case.bodies.A.radius), float(case.bodies.B.radius)
    m_a = d * (first - r_a * q) if math.isfinite(r_a) else math.nan
    m_b = d * (first + r_b * q) if math.isfinite(r_b) else math.nan
    speed = float(case.rolling.speed)
    h = float(system.spacing)
    cells_n, cells_t = p_n, p_t
    if case.discretization.element == "quadratic":  # the quadratics as cell averages (3 nodes, h/3 apart)
        h = 3.0 * h / QUADRATIC_CELLS
        cells_n, cells_t = quadratic_cells(p_n), quadratic_cells(p_t)
    power = 0.0
    for label, model in viscoelastic.bodies(case).items():
        body = getattr(case.bodies, label)
        if body.finite:  # the annulus's loss mode by mode round the circle (quadratic elements)
            power += _annulus_power(system, p_n, p_t if label == "A" else -np.asarray(p_t), body, model, speed)
            continue
        t = cells_t if label == "A" else -cells_t
        power += hysteresis.body_power(h, cells_n, t, model.compliances, model.lengths(speed), model.poisson)
        if viscoelastic.viscoelastic_layer(body):  # the layer's loss beyond the half-plane's (quadratic elements)
            half = 1.5 * float(system.spacing)
            centres = np.asarray(x, dtype=float).reshape(-1, 3)[:, 1]
            sign = 1.0 if label == "A" else -1.0
            power += layer_fourier.remainder_power(
                centres, half, p_n, sign * p_t, float(body.layer_thickness), model.compliances,
                model.lengths(speed), model.poisson,
            )  # fmt: skip
    coefficient = moment / (normal * radius) if normal > 0.0 else math.nan
    balance = dict.fromkeys(("rolling_resistance_force", "shaft_torque_displacement"), math.nan)
    if surface is not None and finite_on_flat(case):  # the finite roller's power balance (uniform grids)
        balance = power_balance.roller_on_flat(
            x, 3.0 * float(system.spacing), r_a, int(d), p_n, p_t, surface[0], surface[1]
        )
        coefficient = balance["rolling_resistance_force"] / normal if normal > 0.0 else math.nan
    return {
        **balance,
        "rolling_resistance_moment": moment,
        "rolling_resistance_moment_a": m_a,
        "rolling_resistance_moment_b": m_b,
        "rolling_resistance_coefficient": coefficient,
        "pressure_centroid": centroid,
        "pressure_shift": -d * centroid,
        "hysteresis_power": power,
    }


def finite_on_flat(case) -> bool:
    """True for a finite body A (quadratic elements) against a rigid flat B: the scope of
    :func:`.power_balance.roller_on_flat`."""
    a, b = case.bodies.A, case.bodies.B
    return bool(a.finite and b.rigid and math.isinf(float(b.radius)) and case.discretization.element == "quadratic")


def _annulus_power(system, p_n, t, body, model, speed: float) -> float:
    """Hysteresis power per unit |V| [force/length] of a viscoelastic finite cylinder
    (:func:`rolling_cli.references.annulus.hysteresis_power`), tractions p_n, t [stress] on it."""
    shape = body.body_shape
    centres = np.asarray(system.x, dtype=float).reshape(-1, 3)[:, 1]
    return annulus.hysteresis_power(
        centres, 1.5 * float(system.spacing), p_n, t, shape.radius, shape.inner_radius, model.poisson,
        model.compliances, model.lengths(speed),
    )  # fmt: skip
