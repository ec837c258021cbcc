"""Closed forms for friction that depends on the slip speed (tests' references).

* **Full sliding.** When every contact node slips, the contact law on each node
  is p_t = -sgn(s_t) mu(s_a) |p_n| with s_a = |V| |s_t|; with one slip direction
  over the whole contact (|xi| beyond the elastic slip), Q = sum w p_t is

      Q = -sgn(xi) sum_i w_i mu(s_a,i) |p_n,i|

  exactly, for any law. Q/P is then a p_n-weighted mean of mu(s_a,i), so it
  lies within max_i |mu(s_a,i) - mu(|V| |xi|)| of mu(|V| |xi|), and by the mean
  value theorem that is at most |V| max|mu'| max_i |s_t,i - xi|: the rigid-slip
  limit mu(|V| |xi|) P, with the elastic part of the slip as its error.
* **Carter's force at a creepage** (similar bodies, Coulomb mu): the inverse of
  :func:`rolling_cli.references.carter.creepage`,
  |Q|/(mu P) = 1 - (1 - |xi| R* / (mu a))^2 for |xi| < mu a / R*.
"""

from __future__ import annotations

import numpy as np


def full_sliding_force(weights: np.ndarray, p_n: np.ndarray, mu_nodes: np.ndarray, creep: float) -> float:
    """Q [force/length] of full sliding: -sgn(xi) sum w mu(s_a) |p_n| (weights [length], p_n [stress])."""
    return float(-np.sign(creep) * np.sum(weights * mu_nodes * np.abs(p_n)))


def rigid_slip_bound(speed: float, max_slope: float, elastic_slip: float) -> float:
    """Bound on |Q/P - mu(|V| |xi|)| [-] in full sliding: |V| [length/time] times max|mu'| [time/length]
    times max|s_t - xi| [-] (module docstring)."""
    return float(speed * max_slope * elastic_slip)


def carter_force_ratio(creep: float, half_width_a: float, radius: float, mu: float) -> float:
    """Carter's Q/(mu P) [-] at creepage xi [-] (Q has the sign opposite to xi); +-1 beyond full slip."""
    full = mu * half_width_a / radius
    u = min(abs(creep) / full, 1.0)
    return float(-np.sign(creep) * (1.0 - (1.0 - u) ** 2))
