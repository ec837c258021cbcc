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

**Gap.** The exact, linearised (in the displacements and the approach d)
condition that the node lies outside the counterpart, divided by the
positive factor that makes d enter with coefficient -1 (a row scaling, which
leaves the complementarity of gap and pressure unchanged):

    delta_i = g0_i - d + c_i (w_A + w_B)_i + s_i (u_A + u_B)_i

with w the displacement into each body and u its tangential displacement
along its own tau (body B's in its mirror frame). Against a rigid circle of
radius R_B centred at C (below the contact at d = 0) with e = (P - C)/|P - C|:
g0 = (|P - C| - R_B)/e_y, c = -(n . e)/e_y, s = (tau . e)/e_y; a flat is
R_B -> inf, e = (0, 1): g0 = R (1 - cos theta), c = cos theta, s = sin theta.
Two cylinders of radius R facing each other: the vertical gap,
g0 = 2 R (1 - cos theta), c = cos theta, s = sin theta. d is the change of
the distance between the shaft's centre and the counterpart's (its centre,
or its surface for a flat): a measurable approach.

**Slip.** The material of a curved surface moves along it with the hoop
strain eps = du/ds + u_r/R = du/ds - w/R, so the relative slip is
s_t = xi + sgn(V) [d(u_A - u_B)/ds - (w_A/R_A - w_B/R_B)], xi = (V_A - V_B)/|V|
with V = omega R the rigid surface speeds: the half-space's definition as
R -> inf. The extra term is a finite body's change of rolling radius (a
compressed rubber roller's "overdrive").

Known approximations: P = -sum w p_n and Q = sum w p_t are the sums of the
normal and tangential tractions along the arc, not the shaft's vertical and
horizontal resultants (which differ by O((a/R)^2)); internal (conformal)
contact is not modelled.
"""

from __future__ import annotations

import math

import numpy as np

from ..influence import Compliance

__all__ = ["gap_factors", "finite_pair"]


def gap_factors(s: np.ndarray, radius: float, other_radius: float | None) -> tuple[np.ndarray, ...]:
    """(g0 [length], c, s) of the module docstring at arc lengths ``s`` [length] on a finite
    cylinder of ``radius`` R; ``other_radius``: inf for a rigid flat, R_B for a rigid convex circle,
    ``None`` for a finite cylinder of the same radius facing it."""
    theta = np.asarray(s, dtype=float) / radius
    cos, sin = np.cos(theta), np.sin(theta)
    if other_radius is None:
        return 2.0 * radius * (1.0 - cos), cos, sin
    if math.isinf(other_radius):
        return radius * (1.0 - cos), cos, sin
    p = np.stack([radius * sin, radius * (1.0 - cos)], axis=-1)
    rel = p - np.array([0.0, -other_radius])
    dist = np.linalg.norm(rel, axis=-1)
    e = rel / dist[:, None]
    normal = np.stack([sin, -cos], axis=-1)
    tangent = np.stack([cos, sin], axis=-1)
    ey = e[:, 1]
    return (dist - other_radius) / ey, -np.einsum("id,id->i", normal, e) / ey, np.einsum("id,id->i", tangent, e) / ey


def _sum(a, b, sign: float):
    if a is None:
        return None if b is None else sign * b
    return a if b is None else a + sign * b


def _cross(body: Compliance) -> np.ndarray:
    """A finite body's S_nt, which its BEM condensation always forms."""
    if body.S_nt is None:
        raise ValueError("a finite body's compliance needs its coupling blocks")
    return body.S_nt


def finite_pair(
    body_a: Compliance | None,
    body_b: Compliance | None,
    radius_a: float,
    radius_b: float,
    finite_a: bool,
    finite_b: bool,
    coupling: bool,
) -> Compliance:
    """The pair compliance of a finite cylinder and its counterpart (module docstring) [length/stress].

    ``body_a``/``body_b``: each body's own compliance with all four blocks, in its arc's directions
    (``None``: rigid); ``radius_*`` [length] (inf: flat); ``finite_*`` whether the body is a finite
    cylinder. The normal rows carry the exact gap's factors, ``gap0`` the exact profile, and
    ``hoop_n``/``hoop_t`` the hoop strain. ``coupling=False`` leaves out S_nt, S_tn and hoop_n.
    """
    bodies = [b for b in (body_a, body_b) if b is not None]
    ref = bodies[0]
    if finite_a and finite_b:
        if radius_a != radius_b:
            raise ValueError("two finite cylinders in contact must have the same radius")
        g0, c, s = gap_factors(ref.x, radius_a, None)
    elif finite_a:
        g0, c, s = gap_factors(ref.x, radius_a, radius_b)
    elif finite_b:
        g0, c, s = gap_factors(ref.x, radius_b, radius_a)
    else:
        raise ValueError("no finite cylinder in the pair")

    def get(body, name):
        return None if body is None else getattr(body, name)

    # normal and tangential displacements of both bodies per unit p_n and p_t (B carries -p_t)
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
        hoop_t -= _cross(body_a) / radius_a
    if finite_b and body_b is not None:  # B carries -p_t
        hoop_n += body_b.S_nn / radius_b
        hoop_t += _cross(body_b) / radius_b
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
    )
