"""Influence models: condensed surface compliances on the contact nodes.

Every model returns the same small interface, :class:`Compliance`: the node
positions and weights of the contact grid and the four condensed blocks

    [w]   [S_nn  S_nt] [p_n]
    [u] = [S_tn  S_tt] [p_t]

For one body (``body_compliance`` of a model), w is the surface displacement
INTO the body and u the displacement along +x, per unit nodal traction: p_n is
the normal traction (negative in compression), p_t the tangential traction on
that body along +x. For the pair (:func:`combine`), p_t is the traction on body
A (B carries -p_t), w = w_A + w_B is the total normal approach of the surfaces
and u = u_A - u_B the relative tangential displacement of A with respect to B.
Each body is described in its own mirror frame (x along the surface, z into the
body), which isotropic elasticity allows, so identical bodies give identical
blocks and their coupling terms cancel exactly in the pair.

``S_nt``/``S_tn`` are ``None`` when the coupling was not assembled (the effect
is absent or switched off): they are then exactly zero.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, TypeAlias

import numpy as np

#: A compliance block: a dense matrix (np.ndarray), or on a uniform grid a
#: :class:`~rolling_cli.influence.toeplitz.BlockToeplitz` operator (matrix-free), which the
#: solver uses through the same duck-typed operations (``@``, unary minus, ``.T``, ``.shape``).
#: Any to a type checker: numpy's array stubs do not describe such an operator.
Block: TypeAlias = Any


@dataclass(frozen=True)
class Compliance:
    """Condensed compliance blocks [length/stress] on the contact nodes.

    ``x`` and ``weights`` [length] are the contact grid's nodes and quadrature
    weights. ``definite_normal`` says whether S_nn carries a definite rigid
    constant (a body with a fixed support, as the BEM block): only then can the
    normal problem be loaded by an imposed overlap.
    """

    x: np.ndarray
    weights: np.ndarray
    S_nn: Block
    S_tt: Block
    S_nt: Block | None = None
    S_tn: Block | None = None
    definite_normal: bool = False
    #: Finite bodies (:mod:`rolling_cli.influence.finite`): the exact undeformed gap [length] (None: the
    #: parabola x^2 / 2R*), and the curved surfaces' relative hoop strain -(w_A/R_A - w_B/R_B) per unit
    #: p_n and p_t [1/stress], which the slip rows add (times the sign of V) to the strain du/ds.
    gap0: np.ndarray | None = None
    hoop_n: np.ndarray | None = None
    hoop_t: np.ndarray | None = None
    #: The weights [length] of the load P = -(load_n p_n + load_t p_t) that ``normal.load`` prescribes:
    #: a finite cylinder's shaft load (:func:`rolling_cli.influence.finite.shaft_load_weights`); None:
    #: the quadrature weights and no p_t term (the arc sum).
    load_n: np.ndarray | None = None
    load_t: np.ndarray | None = None

    @property
    def coupled(self) -> bool:
        """True when the normal-tangential coupling blocks are present."""
        return self.S_nt is not None


def _add(a: np.ndarray | None, b: np.ndarray | None, sign: float) -> np.ndarray | None:
    if a is None:
        return None if b is None else sign * b
    if b is None:
        return a.copy()
    return a + sign * b


def _direct(a: np.ndarray | None, b: np.ndarray | None) -> np.ndarray:
    """A direct block of the pair, S^A + S^B, of the bodies present (one at least)."""
    total = _add(a, b, 1.0)
    if total is None:
        raise ValueError("at least one body must be deformable")
    return total


def combine(body_a: Compliance | None, body_b: Compliance | None, coupling: bool) -> Compliance:
    """Pair compliance from the two bodies' own ones (``None`` = rigid body).

    S_nn = S_nn^A + S_nn^B and S_tt = S_tt^A + S_tt^B (direct terms add);
    S_nt = S_nt^A - S_nt^B and S_tn = S_tn^A - S_tn^B (B carries -p_t and its u
    enters with a minus), which are the paper's eq. 16-17 and 24-25 written in
    mirror frames. With ``coupling=False`` the cross blocks are not formed.
    """
    bodies = [b for b in (body_a, body_b) if b is not None]
    if not bodies:
        raise ValueError("at least one body must be deformable")
    ref = bodies[0]
    for other in bodies[1:]:
        if other.x.shape != ref.x.shape or not np.array_equal(other.x, ref.x):
            raise ValueError("both bodies must be condensed on the same contact nodes")
    a_nn = body_a.S_nn if body_a is not None else None
    b_nn = body_b.S_nn if body_b is not None else None
    a_tt = body_a.S_tt if body_a is not None else None
    b_tt = body_b.S_tt if body_b is not None else None
    s_nt = s_tn = None
    if coupling:
        s_nt = _add(body_a.S_nt if body_a else None, body_b.S_nt if body_b else None, -1.0)
        s_tn = _add(body_a.S_tn if body_a else None, body_b.S_tn if body_b else None, -1.0)
    return Compliance(
        x=ref.x,
        weights=ref.weights,
        S_nn=_direct(a_nn, b_nn),
        S_tt=_direct(a_tt, b_tt),
        S_nt=s_nt,
        S_tn=s_tn,
        definite_normal=all(b.definite_normal for b in bodies),
    )
