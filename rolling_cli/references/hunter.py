"""Hunter's problem (1961): a rigid cylinder rolling without friction on a viscoelastic half-plane.

Hunter's closed form (J. Appl. Mech. 28, 1961) was not at hand, so this
reference solves his problem by a different route than the solver's:

* the half-plane's compliance is taken in Fourier space with the complex
  creep compliance, J*(k) = J_g + sum_i c_i / (1 - i k b_i), b_i = -sgn(V) |V|
  lambda_i (a steady traction pattern of wavenumber k excites the material at
  omega = k |V|), so the surface displacement of a periodic pressure is
  w~(k) = 2 (1 - nu^2) / |k| J*(k) p~(k), k != 0 (the solver instead convolves
  closed-form real-space kernels with the creep compliance in time);
* the line is a period L (L much longer than the contact and the memory
  lengths |V| lambda_i, so neighbouring cylinders do not interact), cut into
  cells of constant pressure; the cell-averaged kernel at the cell centres is
  an inverse FFT of the spectrum above times the cells' sinc, folded over
  :data:`FOLDS` multiples of the grid's wavenumber range;
* the contact is found by an active-set iteration on the cells (pressure
  >= 0, gap >= 0, the load given), not by the solver's semismooth Newton.

Returns the rolling-resistance coefficient x_c / R (x_c the pressure centroid
measured towards the leading edge), which is Hunter's M / (P R) for a rigid
roller without friction. Units: any consistent set.
"""

from __future__ import annotations

import math

import numpy as np

#: Wavenumber bands folded into the cell kernel (the sinc tail beyond decays like 1/FOLDS^2).
FOLDS = 24


def kernel(
    h: float,
    cells: int,
    period: float,
    glassy: float,
    compliances,
    lengths,
    poisson: float,
    thickness: float | None = None,
) -> np.ndarray:
    """w at cell centres per unit pressure on cell 0, at lags 0..cells-1 and -(cells-1)..-1 (FFT order)
    [length/stress]; ``lengths`` the signed history lengths b_i [length]; ``thickness`` b [length]: a
    layer bonded to a rigid base instead of the half-plane (its normal compliance
    :func:`~rolling_cli.references.layer_fourier.transfer`, the half-plane's times 1 - R_nn / (2 (1 -
    nu^2) / |k|))."""
    m = np.fft.fftfreq(cells, d=1.0 / cells)  # integer wavenumber indices
    total = np.zeros(cells, dtype=complex)
    for q in range(-FOLDS, FOLDS + 1):
        k = 2.0 * np.pi * (m + q * cells) / period
        safe = np.where(k == 0.0, 1.0, k)
        compliance = np.full(k.shape, glassy, dtype=complex)
        for c, b in zip(compliances, lengths, strict=True):
            compliance += c / (1.0 - 1j * k * b)
        spectrum = 2.0 * (1.0 - poisson**2) / np.abs(safe) * compliance * h * np.sinc(k * h / (2.0 * np.pi))
        if thickness is not None:
            from .layer_fourier import remainder

            r_nn = remainder(np.abs(safe), thickness, poisson)[0]
            spectrum = spectrum * (1.0 - r_nn * np.abs(safe) / (2.0 * (1.0 - poisson**2)))
        spectrum[k == 0.0] = 0.0  # the mean displacement is free (the approach unknown takes it)
        total += spectrum
    return np.real(np.fft.ifft(total)) * cells / period


def solve(
    load: float,
    radius: float,
    glassy: float,
    compliances,
    lengths,
    poisson: float,
    h: float,
    period: float,
    thickness: float | None = None,
):
    """Cell centres x [length] and pressures p >= 0 [stress] of the rigid roller (radius R, load P per unit
    length) on the viscoelastic half-plane (or layer of ``thickness`` on a rigid base), by the
    active-set iteration."""
    cells = int(round(period / h))
    x = (np.arange(cells) - cells // 2) * h
    lag = kernel(h, cells, period, glassy, compliances, lengths, poisson, thickness)
    gap0 = x**2 / (2.0 * radius)
    relaxed = glassy + sum(compliances)
    a = math.sqrt(4.0 * load * radius * relaxed * (1.0 - poisson**2) / math.pi)
    active = np.abs(x) < a
    for _ in range(200):
        idx = np.flatnonzero(active)
        w = lag[(idx[:, None] - idx[None, :]) % cells]
        n = idx.size
        system = np.zeros((n + 1, n + 1))
        system[:n, :n] = w
        system[:n, n] = -1.0
        system[n, :n] = h
        rhs = np.concatenate([-gap0[idx], [load]])
        sol = np.linalg.solve(system, rhs)
        p = np.zeros(cells)
        p[idx] = sol[:n]
        near = np.flatnonzero(np.abs(x) < 4.0 * a)
        gap = gap0[near] - sol[n] + lag[(near[:, None] - idx[None, :]) % cells] @ sol[:n]
        new = active.copy()
        new[idx[sol[:n] < 0.0]] = False
        new[near[(gap < 0.0) & ~active[near]]] = True
        if np.array_equal(new, active):
            return x, p
        active = new
    raise RuntimeError("the active-set iteration did not settle")


def rolling_resistance(
    load: float,
    radius: float,
    glassy_young: float,
    relaxed_young: float,
    creep_time: float,
    poisson: float,
    speed: float,
    direction: int = -1,
    cells_per_a: int = 120,
    thickness: float | None = None,
) -> float:
    """Rolling-resistance coefficient x_c / R [-] of a rigid cylinder (radius R [length], load P
    [force/length]) rolling at |V| [length/time] without friction on a standard linear solid
    (E_g, E_r [stress], creep time tau_c [time], nu). ``cells_per_a``: cells per relaxed Hertz
    half-width; ``thickness`` b [length]: a layer of the material bonded to a rigid base instead of
    the half-plane (the cells and the period are still set by the relaxed Hertz half-width)."""
    glassy = 1.0 / glassy_young
    c = 1.0 / relaxed_young - glassy
    ell = speed * creep_time
    a = math.sqrt(4.0 * load * radius * (1.0 - poisson**2) / (math.pi * relaxed_young))
    h = a / cells_per_a
    period = max(40.0 * a, 30.0 * ell)
    x, p = solve(load, radius, glassy, [c], [-direction * ell], poisson, h, period, thickness)
    centroid = float(np.sum(p * x) * h / load)
    return -direction * centroid / radius
