"""Sensitivities of a converged solve with a slip-speed friction law mu(s_a) (issue 24, item 1).

The Coulomb derivatives (:mod:`rolling_cli.solver.sensitivity`) eliminate the slip
tractions with p_t = -mu sigma p_n, which a law mu(s_a), s_a = |V| |s_t|, does
not allow. Here the implicit derivatives come from the velocity Newton's own
linearisation (:func:`rolling_cli.solver.velocity.velocity_system`, the
d mu/d s_a term included): at fixed node states the residual R(z, theta) = 0
of the converged solution gives A dz/dtheta = -dR/dtheta at fixed z, with A
the Jacobian of that system. The slip rows are R_i = p_t,i - sigma_i mu(s_a,i)
|lambda_n,i| (in stress units, as the velocity rows), so

* the law's scale, mu(s) -> (1 + e) mu(s) (the whole law scaled, mu_static and
  mu_kinetic together, at e = 0): -dR_i/de = sigma_i mu(s_a,i) |lambda_n,i|;
  ``dQ_dmu`` is d/d mu_static along that scaling, (1/mu_static) d/de, which is
  Coulomb's dQ/dmu for a flat law (mu_kinetic = mu_static);
* the rolling speed |V| (``dQ_dV``), which enters only through s_a = |V| |s_t|:
  -dR_i/d|V| = sigma_i mu'(s_a,i) |s_t,i| |lambda_n,i|;
* the creepage xi (``dQ_dxi``): the system's ``creep_column``; a prescribed
  force Q (force control): the force row's right-hand side, 1/zone length.

The adhesion, contact and load rows hold neither mu nor |V|. An
overlap-controlled solve is differentiated as the load-controlled problem at
its own load (P held, as :mod:`rolling_cli.solver.sensitivity` does). The
velocity system is assembled and factorised once more here (dense LU, all
three columns at once): the Newton's kept factorisation is of an earlier
step's matrix (:mod:`rolling_cli.solver.reuse`), not of this one. Force control
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
P-derivatives with a law (NaN): layers, overlap control and finite cylinders,
whose fixed-state derivative misses the edge motion (3.7 % on dxi/dP of a
viscoelastic case, 46 % on Carter's dQ/dP) and which no homogeneity corrects.
A node exactly on a zone boundary: the one-sided derivative of the solver's
own node states (:func:`~rolling_cli.solver.formulation.node_sets`).
"""

from __future__ import annotations

import math

import numpy as np

from .formulation import Problem, State, evaluate, node_sets, traction_scales
from .linalg import solve_dense
from .sensitivity import UNDEFINED, Sensitivities, Tangent, _edge_derivative
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
    load = problem.system.load(state.p_n, state.p_t)  # P as normal.load prescribes it
    if not load > 0.0 or problem.friction is None or not problem.tangential:
        return UNDEFINED
    q = float(w @ state.p_t)
    # an overlap-controlled solve as the load-controlled problem at its own load (P held, as
    # :mod:`rolling_cli.solver.sensitivity` does); a prescribed force held as Q itself
    held = problem.held(force=("load", q) if force_control else None, load=load if problem.normal else problem.load)
    ev = evaluate(held, state, traction_scales(held, state))
    system, scale, speed_column = law_columns(held, state, ev)
    if force_control:
        control = np.zeros(system.rhs.size)
        control[system.col_creep] = 1.0 / held.system.zone_length
    else:
        control = system.creep_column
    dz = solve_dense(system.matrix, np.column_stack([control, scale / problem.friction.law.mu_static, speed_column]))
    tangents = [_tangent(held, system, np.asarray(dz).reshape(system.rhs.size, 3)[:, k]) for k in range(3)]
    speed = problem.friction.speed
    # homogeneity (module docstring): P dF/dP = degree(F) F - weight dF/d(xi or Q) + (V/2) dF/dV
    weight = q if force_control else 0.5 * state.creep
    normal = _normal(problem, state, system.contact, tangents, weight, speed, load, half_width)
    da, dp0 = normal if self_similar else (math.nan, math.nan)
    if force_control:
        dxi_dq, dxi_dmu, dxi_dv = (t.d_creep for t in tangents)
        dxi_dp = (0.5 * state.creep - weight * dxi_dq + 0.5 * speed * dxi_dv) / load if self_similar else math.nan
        inverse = _ratio(1.0, dxi_dq)
        return Sensitivities(
            inverse, -dxi_dmu * inverse, -dxi_dp * inverse, dxi_dq, dxi_dmu, dxi_dp, da, dp0,
            dQ_dV=-dxi_dv * inverse, dxi_dV=dxi_dv,
        )  # fmt: skip
    dq_dxi, dq_dmu, dq_dv = (t.d_force for t in tangents)
    dq_dp = (q - weight * dq_dxi + 0.5 * speed * dq_dv) / load if self_similar else math.nan
    inverse = _ratio(1.0, dq_dxi)
    return Sensitivities(
        dq_dxi, dq_dmu, dq_dp, inverse, -dq_dmu * inverse, -dq_dp * inverse, da, dp0,
        dQ_dV=dq_dv, dxi_dV=-dq_dv * inverse,
    )  # fmt: skip


def _ratio(numerator: float, denominator: float) -> float:
    return numerator / denominator if denominator != 0.0 else math.nan


def _tangent(problem: Problem, system, dz: np.ndarray) -> Tangent:
    """The :class:`~rolling_cli.solver.sensitivity.Tangent` of the velocity system's solution
    derivative ``dz`` (tractions [stress/theta], overlap, Q and xi along theta)."""
    contact_system = problem.system
    nc, nt = system.contact.size, system.traction.size
    dp_n = np.zeros(contact_system.size)
    dp_n[system.contact] = dz[:nc]
    dp_t = np.zeros(contact_system.size)
    dp_t[system.traction] = dz[nc : nc + nt]
    d_overlap = float(dz[system.col_overlap]) / contact_system.penalty_n if system.col_overlap is not None else 0.0
    d_creep = float(dz[system.col_creep]) / contact_system.penalty_t if system.col_creep is not None else 1.0
    return Tangent(dp_n, dp_t, d_overlap, float(contact_system.weights @ dp_t), d_creep)


def _normal(problem, state, contact, tangents, weight, speed, load, half_width) -> tuple[float, float]:
    """(da/dP, dp0/dP) of a load on two half-spaces by homogeneity (module docstring; a and p0 of
    degree 1/2): the pressure's own derivatives along xi or Q and |V| (zero for similar bodies,
    else a's by the active-set change argument of :mod:`rolling_cli.solver.sensitivity`)."""
    peak = int(np.argmin(state.p_n))
    control, _, along_speed = tangents
    d_a = d_p0 = d_a_v = d_p0_v = 0.0
    if np.any(control.dp_n) or np.any(along_speed.dp_n):  # the pressure moves (coupled)
        d_a = _edge_derivative(problem.system, state, contact, control)
        d_a_v = _edge_derivative(problem.system, state, contact, along_speed)
        d_p0, d_p0_v = float(-control.dp_n[peak]), float(-along_speed.dp_n[peak])
    da = (0.5 * half_width - weight * d_a + 0.5 * speed * d_a_v) / load
    dp0 = (0.5 * float(-state.p_n[peak]) - weight * d_p0 + 0.5 * speed * d_p0_v) / load
    return da, dp0
