"""The contact of a finite cylinder: exact geometry and kinematics on the contact arc.

A finite cylinder (``shape = "cylinder"``, :mod:`.shapes`) is condensed on
contact nodes at arc lengths s along its outer circle, in the arc's own
directions (:mod:`rolling_cli.influence.bem.cylinder`). Its counterpart is
rigid (a flat or a convex circle), or a finite cylinder of the same radius
(then the two arcs' nodes at equal s face each other across the flat
mid-plane). In each body's own frame the contact centre is at the origin, the
body's centre at distance R along its inward normal, and a node at s sits at
the angle theta = s / R, with outward normal n = (sin theta, -cos theta) and
tangent tau = (cos theta, sin theta) (drawn for the upper body A; B is its
mirror image).

**Tractions** act along the arc's own normal and tangent at each node (p_n,
p_t), the issue's "normal and tangential directions of the arc", as the
linear theory's Signorini condition on the undeformed surface.

**Gap.** The exact, linearised (in the displacements and the approach d)
condition that the node lies outside the counterpart, measured along the
counterpart's normal N (out of the finite body; vertical against a flat or a
twin, towards the centre of a rigid circle) and divided by the positive
factor that makes d enter with coefficient -1 (a row scaling, which leaves
the complementarity of gap and pressure unchanged):

    delta_i = g0_i - d + c_i (w_A + w_B)_i + s_i (u_A + u_B)_i

with w the displacement into each body and u its tangential displacement
along its own tau (body B's in its mirror frame), c = (n . N)/(-N_y),
s = (tau . N)/N_y. Against a rigid circle of radius R_B centred at C (below
the contact at d = 0), N = -(P - C)/|P - C| and g0 = (|P - C| - R_B)/(-N_y);
a flat is R_B -> inf, N = (0, -1): g0 = R (1 - cos theta), c = cos theta,
s = sin theta. Two cylinders of radius R facing each other: the vertical
gap, g0 = 2 R (1 - cos theta), c = cos theta, s = sin theta. d is the change
of the distance between the shaft's centre and the counterpart's (its
centre, or its surface for a flat): a measurable approach.

**Slip.** The material of a curved surface moves along it with the hoop
strain eps = du/ds + u_r/R = du/ds - w/R, so the relative slip is
s_t = xi + sgn(V) [d(u_A - u_B)/ds - (w_A/R_A - w_B/R_B)], xi = (V_A - V_B)/|V|
with V = omega R the rigid surface speeds: the half-space's definition as
R -> inf. For a solid roller the radial term cancels the curved surface's
extra tangential displacement to O(a/R); for a cover on a rigid core it is
the cover's change of rolling radius.

**Loads on the shaft.** P and Q are the resultants on the shaft. By the
equilibrium of the body (the bore's reaction balances the contact tractions:
tests/test_finite_shaft.py), Q = sum w p_t, the sum along the arc, is exactly
the torque the shaft transmits divided by R (``shaft_torque``: the pressure,
radial, has no moment about the centre), the creep force a rig's torque
meter reads (to first order in the displacements: the tractions' displaced
points add T_u, :mod:`rolling_cli.model.power_balance`). P is the force on
the shaft's bearing along the line of centres (``shaft_load``):
P = -(load_n p_n + load_t p_t) with load_n = w cos theta and
load_t = -w sin theta (+ for a finite B alone, which carries -p_t:
:func:`shaft_load_weights`), the pressure's projection plus the tangential
traction's. ``normal.load`` prescribes this P: the solver's load row has these
weights (:meth:`rolling_cli.solver.system.ContactSystem.load`), so it couples
the normal load to the tangential unknowns, and the result's ``normal_load``
is this P; the arc sum -sum w p_n is ``arc_load``. They differ by 1.7 % in a
hollow roller (nu = 0.3, a/R = 0.29, Q/(mu P) = 0.5; arc sum above P), 1.3 %
for a cover at a/R = 0.24, 0.5 % the other way at Q = 0, 6e-6 at R/a = 1340
(tests/test_finite_load.py: the bore's reaction, from the whole BEM body,
equals normal.load within 7.7e-9 and 2.1e-7, measured; bound 1e-5). Two finite cylinders: P is the mean of the
two shafts' loads, sum w cos theta (-p_n) (they differ by 2 sum w p_t sin
theta, an O(a/R) ambiguity of the arc's directions); ``shaft_load`` is A's.
With ``effects.coupling = "off"`` the p_t term goes with the coupling (the
decoupled stages hold p_t = 0 while they meet P). The force on the bearing
along x is ``shaft_tangential_load``: Q's projection plus the pressure's, P e
/ R for a pressure centroid e off the line of centres. The tangential traction
shifts the pressure on a curved body (by e = -0.096 a in that hollow roller;
-0.075 a at nu = 0.5: not a Dundurs effect), so that force exceeds Q by 0.11 =
17 % of Q there (1.2 % for a cover at a/R = 0.19), and by nothing without a
tangential load (3e-6 of P).
Tried and not taken: tractions along the counterpart's normal and
tangent (``traction_frame = "contact"``: vertical against a flat, which makes
P and Q the shaft's resultants). At a/R = 0.3 its creepage is 4 % off the
arc frame's (the direction of the pressure on a surface that the contact
turns by a/R rad is an O(a/R) ambiguity of linear elasticity) and it
converges only like the element size (0.6 % between 100 and 200 elements,
against 0.02 % in the arc frame). Internal (conformal) contact is not
modelled.
"""

from __future__ import annotations

import math

import numpy as np

from . import Compliance

__all__ = ["contact_frame", "arc_frame", "finite_pair", "shaft_load_weights", "shaft_quantities"]


def contact_frame(s: np.ndarray, radius: float, other_radius: float | None) -> tuple[np.ndarray, np.ndarray]:
    """The undeformed gap g0 [length] (divided by -N_y, module docstring) and the contact normal N
    (n, 2) at arc lengths ``s`` [length] on a finite cylinder of ``radius`` R, in its own frame.

    N points out of the finite body into the counterpart: (0, -1) against a flat (``other_radius``
    inf) or a finite cylinder of the same radius facing it (``None``: the flat mid-plane), and from
    the node towards the centre of a rigid convex circle of radius R_B.
    """
    theta = np.asarray(s, dtype=float) / radius
    cos, sin = np.cos(theta), np.sin(theta)
    down = np.broadcast_to(np.array([0.0, -1.0]), theta.shape + (2,))
    if other_radius is None:
        return 2.0 * radius * (1.0 - cos), down
    if math.isinf(other_radius):
        return radius * (1.0 - cos), down
    p = np.stack([radius * sin, radius * (1.0 - cos)], axis=-1)
    rel = p - np.array([0.0, -other_radius])
    dist = np.linalg.norm(rel, axis=-1)
    e = rel / dist[:, None]
    return (dist - other_radius) / e[:, 1], -e


def arc_frame(s: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """The outward normal nu and the tangent tau (n, 2) of a finite body's outer circle at arc
    lengths ``s`` [length], in its own frame (the body above its contact)."""
    theta = np.asarray(s, dtype=float) / radius
    cos, sin = np.cos(theta), np.sin(theta)
    return np.stack([sin, -cos], axis=-1), np.stack([cos, sin], axis=-1)


def shaft_load_weights(
    s: np.ndarray, weights: np.ndarray, radius: float, finite_a: bool
) -> tuple[np.ndarray, np.ndarray]:
    """The weights (load_n, load_t) [length] of the shaft load P = -(load_n p_n + load_t p_t) of the
    finite body at arc lengths ``s`` [length] with quadrature ``weights`` [length] on its circle of
    ``radius`` [length]: load_n = w cos theta and load_t = -w sin theta for a finite A, +w sin theta
    for a finite B alone (which carries -p_t), theta = s / R. P is the component along the line of
    centres of the contact tractions' resultant on the body (``shaft_load``, module docstring)."""
    theta = np.asarray(s, dtype=float) / radius
    w = np.asarray(weights, dtype=float)
    return w * np.cos(theta), (-1.0 if finite_a else 1.0) * w * np.sin(theta)


def _sum(a, b, sign: float):
    if a is None:
        return None if b is None else sign * b
    return a if b is None else a + sign * b


def _cross(body: Compliance, name: str) -> np.ndarray:
    """A finite body's coupling block, which its BEM condensation always forms."""
    block = getattr(body, name)
    if block is None:
        raise ValueError("a finite body's compliance needs its coupling blocks")
    return block


def _in_contact_frame(body: Compliance, nu, tau, normal, tangent) -> Compliance:
    """A body's arc-frame compliance with its columns for tractions along the contact normal N and
    tangent T: p^arc_n = p_N (N . nu) + p_T (T . nu), p^arc_t = p_N (N . tau) + p_T (T . tau)."""

    def dot(a, b):
        return np.einsum("id,id->i", a, b)

    n_nu, n_tau, t_nu, t_tau = dot(normal, nu), dot(normal, tau), dot(tangent, nu), dot(tangent, tau)
    s_nt, s_tn = _cross(body, "S_nt"), _cross(body, "S_tn")
    return Compliance(
        x=body.x,
        weights=body.weights,
        S_nn=body.S_nn * n_nu + s_nt * n_tau,
        S_nt=body.S_nn * t_nu + s_nt * t_tau,
        S_tn=s_tn * n_nu + body.S_tt * n_tau,
        S_tt=s_tn * t_nu + body.S_tt * t_tau,
        definite_normal=body.definite_normal,
    )


def finite_pair(
    body_a: Compliance | None,
    body_b: Compliance | None,
    radius_a: float,
    radius_b: float,
    finite_a: bool,
    finite_b: bool,
    coupling: bool,
    traction_frame: str = "arc",
) -> Compliance:
    """The pair compliance of a finite cylinder and its counterpart (module docstring) [length/stress].

    ``body_a``/``body_b``: each body's own compliance with all four blocks, in its arc's directions
    (``None``: rigid); ``radius_*`` [length] (inf: flat); ``finite_*`` whether the body is a finite
    cylinder. The tractions act along the arc's normal and tangent (``traction_frame = "arc"``,
    the model) or along the contact's (``"contact"``: vertical against a flat, kept for the
    comparison in the module docstring); the normal rows carry the exact gap's factors, ``gap0``
    the exact profile, and ``hoop_n``/``hoop_t`` the hoop strain. ``coupling=False`` leaves out
    S_nt, S_tn and hoop_n.
    """
    bodies = [b for b in (body_a, body_b) if b is not None]
    ref = bodies[0]
    if finite_a and finite_b:
        if radius_a != radius_b:
            raise ValueError("two finite cylinders in contact must have the same radius")
        radius, other = radius_a, None
    elif finite_a or finite_b:
        radius, other = (radius_a, radius_b) if finite_a else (radius_b, radius_a)
    else:
        raise ValueError("no finite cylinder in the pair")
    g0, normal = contact_frame(ref.x, radius, other)
    nu, tau = arc_frame(ref.x, radius)
    tangent = np.stack([-normal[:, 1], normal[:, 0]], axis=-1)
    # the gap along N, scaled so that the approach enters with -1: c w + s u_t
    c = np.einsum("id,id->i", nu, normal) / -normal[:, 1]
    s = np.einsum("id,id->i", tau, normal) / normal[:, 1]
    if traction_frame == "contact":  # tractions along N and T (else along the arc: nu, tau)
        body_a = None if body_a is None else _in_contact_frame(body_a, nu, tau, normal, tangent)
        body_b = None if body_b is None else _in_contact_frame(body_b, nu, tau, normal, tangent)

    def get(body, name):
        return None if body is None else getattr(body, name)

    # normal and tangential displacements of both bodies per unit p_N and p_T (B carries -p_T)
    w_n = _sum(get(body_a, "S_nn"), get(body_b, "S_nn"), 1.0)
    w_t = _sum(get(body_a, "S_nt"), get(body_b, "S_nt"), -1.0)
    u_sum_n = _sum(get(body_a, "S_tn"), get(body_b, "S_tn"), 1.0)
    u_sum_t = _sum(get(body_a, "S_tt"), get(body_b, "S_tt"), -1.0)
    s_nn = c[:, None] * w_n + s[:, None] * u_sum_n
    s_nt = c[:, None] * w_t + s[:, None] * u_sum_t
    s_tn = _sum(get(body_a, "S_tn"), get(body_b, "S_tn"), -1.0)
    s_tt = _sum(get(body_a, "S_tt"), get(body_b, "S_tt"), 1.0)
    # hoop strain -(w_A/R_A - w_B/R_B); only finite bodies have it
    hoop_n = np.zeros_like(s_nn)
    hoop_t = np.zeros_like(s_nn)
    if finite_a and body_a is not None:
        hoop_n -= body_a.S_nn / radius_a
        hoop_t -= _cross(body_a, "S_nt") / radius_a
    if finite_b and body_b is not None:  # + w_B / R_B; B carries -p_T: -S_nt^B p_T / R_B (test_finite_load.py)
        hoop_n += body_b.S_nn / radius_b
        hoop_t -= _cross(body_b, "S_nt") / radius_b
    # normal.load prescribes the finite body's shaft load; two finite bodies: the mean of their shafts'
    # (no p_t term); without the coupling its p_t term goes too (the decoupled stages hold p_t = 0)
    load_n, load_t = shaft_load_weights(ref.x, ref.weights, radius, finite_a)
    keep_t = coupling and not (finite_a and finite_b)
    return Compliance(
        x=ref.x,
        weights=ref.weights,
        S_nn=s_nn,
        S_tt=s_tt,
        S_nt=s_nt if coupling else None,
        S_tn=s_tn if coupling else None,
        definite_normal=True,
        gap0=g0,
        hoop_n=hoop_n if coupling else None,
        hoop_t=hoop_t,
        load_n=load_n,
        load_t=load_t if keep_t else None,
    )


def shaft_quantities(case, x, weights, p_n, p_t, centre: float, half_width: float) -> dict[str, float]:
    """Result attributes of a finite cylinder (NaN for every one when the case has none).

    The resultants of the contact tractions p_n nu + p_t tau (the arc's frame) on the finite body
    [force/length], in its shaft's frame (y along the line of centres, the body above its contact in
    its own frame): ``shaft_load`` = sum w (-p_n cos + p_t' sin), the compressive load on its shaft,
    and ``shaft_tangential_load`` the force on body A along x, sum w (p_n sin + p_t cos) for a finite
    A (p_t' = p_t; a finite B alone carries p_t' = -p_t); ``shaft_torque`` [moment/length] = R sum w p_t,
    the moment about the shaft's axis that the shaft transmits (the pressure, along the radius, has
    none), so Q = shaft_torque / R (tests/test_finite_shaft.py checks all three against the bore's
    reaction). ``contact_angle`` and ``contact_arc`` [rad]: the contact's centre and extent on the
    finite body's outer circle. ``arc_load`` [force/length]: the arc sum -sum w p_n (the normal load
    P is the shaft load, which ``normal.load`` prescribes: :func:`shaft_load_weights`).
    """
    a, b = case.bodies.A, case.bodies.B
    names = ("shaft_load", "shaft_tangential_load", "shaft_torque", "contact_angle", "contact_arc", "arc_load")
    if not (a.shape == "cylinder" or b.shape == "cylinder"):
        return dict.fromkeys(names, math.nan)
    finite_a = a.shape == "cylinder"
    radius = float(a.radius if finite_a else b.radius)
    nu, tau = arc_frame(x, radius)
    w = np.asarray(weights, dtype=float)
    p_body = np.asarray(p_t) if finite_a else -np.asarray(p_t)  # B carries -p_t in its own frame
    force = w @ (np.asarray(p_n)[:, None] * nu + p_body[:, None] * tau)  # on the finite body, its own frame
    load = float(force[1])
    tangential = float(force[0] if finite_a else -force[0])
    torque = radius * float(w @ np.asarray(p_t))
    arc = -float(w @ np.asarray(p_n))
    values = (load, tangential, torque, centre / radius, 2.0 * half_width / radius, arc)
    return dict(zip(names, values, strict=True))
