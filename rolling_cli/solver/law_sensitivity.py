"""Sensitivities of a converged solve with a slip-speed friction law mu(s_a) (issue 24, item 1).

The Coulomb derivatives (:mod:`rolling_cli.solver.sensitivity`) eliminate the slip
tractions with p_t = -mu sigma p_n, which a law mu(s_a), s_a = |V| |s_t|, does
not allow. Here the implicit derivatives come from the velocity Newton's own
linearisation (:func:`rolling_cli.solver.velocity.velocity_system`, the
d mu/d s_a term included): at fixed node states the residual R(z, theta) = 0
of the converged solution gives A dz/dtheta = -dR/dtheta at fixed z, with A
the Jacobian of that system. The slip rows are R_i = p_t,i - sigma_i mu(s_a,i)
|lambda_n,i| (in stress units, as the velocity rows), so

* the law's scale, mu(s) -> (1 + e) mu(s) (``dQ_dmu``: the whole law scaled,
  mu_static and mu_kinetic together, at e = 0): -dR_i/de = sigma_i mu(s_a,i) |lambda_n,i|;
* the rolling speed |V| (``dQ_dV``), which enters only through s_a = |V| |s_t|:
  -dR_i/d|V| = sigma_i mu'(s_a,i) |s_t,i| |lambda_n,i|;
* the creepage xi (``dQ_dxi``): the system's ``creep_column``; a prescribed
  force Q (force control): the force row's right-hand side, 1/zone length.

The adhesion, contact and load rows hold neither mu nor |V|. Force control
gives dxi/dQ, dxi/dmu, dxi/dV from the bordered system (creepage unknown),
creepage control dQ/dxi, dQ/dmu, dQ/dV; the other set follows by the implicit
function theorem as in :mod:`rolling_cli.solver.sensitivity`.

The load: the fixed-state dQ/dP misses the motion of Carter's leading edge
(:mod:`rolling_cli.solver.sensitivity`, "Moving contact edges"). For a load on
two half-spaces rollc's mapping is homogeneous in the load once the speed is
scaled with it too: tractions scale with l^1/2 under P -> l P, so does the
normalised slip s_t, and s_a = |V| |s_t| is unchanged when |V| -> l^-1/2 |V|:
Q(l P, l^1/2 xi, l^-1/2 V) = l Q(P, xi, V). Differentiated at l = 1,

    P dQ/dP = Q - (xi/2) dQ/dxi + (V/2) dQ/dV          (creepage control),
    P dxi/dP = xi/2 - Q dxi/dQ + (V/2) dxi/dV          (force control),

exact derivatives of ``rollc solve``'s result from the fixed-grid ones in xi,
Q and V. The pressure of such a pair does not depend on the tangential
problem: da/dP = a/(2P), dp0/dP = p0/(2P). Other problems get no
P-derivatives with a law (NaN): their fixed-state derivative misses the edge
motion and no homogeneity corrects it.
"""

from __future__ import annotations

import math

import numpy as np

from .formulation import Problem, State, evaluate, node_sets, traction_scales
from .linalg import solve_dense
from .sensitivity import UNDEFINED, Sensitivities
from .velocity import velocity_system


def law_columns(problem: Problem, state: State, ev) -> tuple:
    """(the velocity system, -dR/de of the law's scale, -dR/d|V|) at the converged ``state`` (module
    docstring): [stress] and [stress/(length/time)] on the slip rows, zero elsewhere."""
    assert problem.friction is not None and ev.slip is not None and ev.capacity is not None
    system = velocity_system(problem, state, ev)
    law, speed = problem.friction.law, problem.friction.speed
    nodes = system.traction[system.slip_rows - system.contact.size]
    sigma = node_sets(problem, state, ev).sigma[nodes]  # the slip rows' own directions
    s_abs = np.abs(ev.slip[nodes])
    s_a = speed * s_abs
    scale = np.zeros(system.rhs.size)
    scale[system.slip_rows] = sigma * law.mu(s_a) * ev.capacity[nodes]
    speed_column = np.zeros(system.rhs.size)
    speed_column[system.slip_rows] = sigma * law.dmu_ds(s_a) * s_abs * ev.capacity[nodes]
    return system, scale, speed_column


def law_sensitivities(
    problem: Problem, state: State, force_control: bool, self_similar: bool, half_width: float
) -> Sensitivities:
    """The derivatives of a converged solve with a slip-speed law (module docstring).

    ``problem`` the solve's (``friction`` set, tangential), ``force_control`` whether the case
    prescribes Q (held as the force itself), ``self_similar`` a load on two half-spaces (then the
    P-derivatives by homogeneity, else NaN), ``half_width`` the contact half-width [length].
    Raises ``numpy.linalg.LinAlgError`` on a singular matrix.
    """
    w = problem.system.weights
    load = float(-(w @ state.p_n))
    if not load > 0.0 or problem.friction is None or not problem.tangential:
        return UNDEFINED
    q = float(w @ state.p_t)
    held = problem.held(force=("load", q) if force_control else None)
    ev = evaluate(held, state, traction_scales(held, state))
    system, scale, speed_column = law_columns(held, state, ev)
    nc, nt = system.contact.size, system.traction.size
    if force_control:
        control = np.zeros(system.rhs.size)
        control[system.col_creep] = 1.0 / held.system.zone_length
    else:
        control = system.creep_column
    dz = solve_dense(system.matrix, np.column_stack([control, scale, speed_column]))
    dz = np.asarray(dz).reshape(system.rhs.size, 3)
    if force_control:
        dxi = dz[system.col_creep] / held.system.penalty_t  # dxi/dQ, dxi/de, dxi/dV
        return _from_creep(dxi, state.creep, q, load, problem.friction.speed, self_similar, half_width, state)
    dq = w[system.traction] @ dz[nc : nc + nt]  # dQ/dxi, dQ/de, dQ/dV
    return _from_force(dq, state.creep, q, load, problem.friction.speed, self_similar, half_width, state)


def _ratio(numerator: float, denominator: float) -> float:
    return numerator / denominator if denominator != 0.0 else math.nan


def _normal(load: float, self_similar: bool, half_width: float, state: State) -> tuple[float, float]:
    """(da/dP, dp0/dP) of a load on two half-spaces (module docstring), else NaN."""
    if not self_similar:
        return math.nan, math.nan
    return 0.5 * half_width / load, 0.5 * float(-state.p_n.min()) / load


def _from_force(dq, xi, q, load, speed, self_similar, half_width, state) -> Sensitivities:
    """Both sets from Q's derivatives (creepage control)."""
    dq_dxi, dq_dmu, dq_dv = (float(v) for v in dq)
    dq_dp = (q - 0.5 * xi * dq_dxi + 0.5 * speed * dq_dv) / load if self_similar else math.nan
    inverse = _ratio(1.0, dq_dxi)
    da, dp0 = _normal(load, self_similar, half_width, state)
    return Sensitivities(
        dq_dxi, dq_dmu, dq_dp, inverse, -dq_dmu * inverse, -dq_dp * inverse, da, dp0,
        dQ_dV=dq_dv, dxi_dV=-dq_dv * inverse,
    )  # fmt: skip


def _from_creep(dxi, xi, q, load, speed, self_similar, half_width, state) -> Sensitivities:
    """Both sets from the creepage's derivatives (force control)."""
    dxi_dq, dxi_dmu, dxi_dv = (float(v) for v in dxi)
    dxi_dp = (0.5 * xi - q * dxi_dq + 0.5 * speed * dxi_dv) / load if self_similar else math.nan
    inverse = _ratio(1.0, dxi_dq)
    da, dp0 = _normal(load, self_similar, half_width, state)
    return Sensitivities(
        inverse, -dxi_dmu * inverse, -dxi_dp * inverse, dxi_dq, dxi_dmu, dxi_dp, da, dp0,
        dQ_dV=-dxi_dv * inverse, dxi_dV=dxi_dv,
    )  # fmt: skip
