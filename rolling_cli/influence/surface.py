"""Each deformable body's own surface displacements on the contact nodes, from its own compliance.

For the solved tractions (p_n on both bodies, p_t on A, -p_t on B) each body's
surface displacement is its own blocks applied to its own tractions:

    w_X = S_nn^X p_n + S_nt^X (+-p_t),   u_X = S_tn^X p_n + S_tt^X (+-p_t)

(+ for A, - for B): w [length] into the body, u [length] along +x (a finite
cylinder's: along its arc's tangent, in its arc frame; body B's in its mirror
frame, :mod:`rolling_cli.influence.finite`). They are the parts of the pair's
(:func:`rolling_cli.influence.combine`): w = w_A + w_B and u = u_A - u_B are
exactly the pair's, so the gap they draw is the solver's gap.

The half-plane models (elastic closed form, viscoelastic steady-rolling
kernels) build each body as a pair with a rigid counterpart (the pair's blocks
are the sum of the bodies'), with the same coupling as the solved pair; their
displacements are relative to the model's datum (the log kernel's reference
length: a rigid shift in 2D). The BEM bodies (half-space blocks, layers,
finite cylinders) are :func:`rolling_cli.influence.build.deformable_body`, the
memoised compliance the solve used (not rebuilt).
"""

from __future__ import annotations

import numpy as np

from ..model.viscoelastic import bodies as viscoelastic_bodies
from ..model.viscoelastic import material

__all__ = ["body_displacements"]


def _apply(block, values: np.ndarray) -> np.ndarray:
    return np.zeros_like(values) if block is None else np.asarray(block @ values)


def _halfplane_alone(case, the_plan, label: str):
    """Body ``label``'s half-plane compliance as a pair with a rigid counterpart (the pair's convention:
    its u is u_A, or -u_B for B)."""
    from . import build

    own = material(getattr(case.bodies, label))
    pair = (own, None) if label == "A" else (None, own)
    coupling = the_plan.effects.coupling
    if viscoelastic_bodies(case):
        return build._viscoelastic(
            the_plan.grid, pair[0], pair[1], float(case.rolling.speed), case.rolling.direction, coupling
        )
    return build._halfplane(the_plan.grid, pair[0], pair[1], coupling)


def body_displacements(case, the_plan, p_n: np.ndarray, p_t: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """{label: (w, u)} [length] of each deformable body of ``case`` ("A", "B"; a rigid one is left out)
    for the nodal tractions ``p_n``, ``p_t`` [stress] on the plan's contact grid (p_t on A)."""
    out = {}
    for label in ("A", "B"):
        body = getattr(case.bodies, label)
        if body.rigid:
            continue
        if the_plan.effects.influence == "half-plane":
            pair = _halfplane_alone(case, the_plan, label)
            w = _apply(pair.S_nn, p_n) + _apply(pair.S_nt, p_t)
            u = _apply(pair.S_tn, p_n) + _apply(pair.S_tt, p_t)
            out[label] = (w, u if label == "A" else -u)
            continue
        from .build import deformable_body

        own, _ = deformable_body(case, the_plan, body)
        traction = p_t if label == "A" else -p_t
        coupled = the_plan.effects.coupling  # the pair's cross blocks only where the solve had them
        w = _apply(own.S_nn, p_n) + _apply(own.S_nt if coupled else None, traction)
        u = _apply(own.S_tn if coupled else None, p_n) + _apply(own.S_tt, traction)
        out[label] = (w, u)
    return out
