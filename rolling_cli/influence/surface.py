"""Each deformable body's own surface displacements on the contact nodes, from its own compliance.

For the solved tractions (p_n on both bodies, p_t on A, -p_t on B) each body's
surface displacement is its own blocks applied to its own tractions:

    w_X = S_nn^X p_n + S_nt^X (+-p_t),   u_X = S_tn^X p_n + S_tt^X (+-p_t)

(+ for A, - for B): w [length] into the body, u [length] along +x (a finite
cylinder's: along its arc's tangent, in its arc frame; body B's in its mirror
frame, :mod:`rolling_cli.influence.finite`). They are the parts of the pair's
(:func:`rolling_cli.influence.combine`): w = w_A + w_B and u = u_A - u_B are
exactly the pair's, so the gap they draw is the solver's gap.

The elastic closed-form half-planes scale the solved pair's blocks (the
same two kernels, :func:`_elastic_halfplanes`); otherwise a half-plane model
(viscoelastic steady-rolling kernels; an elastic pair whose cross kernel
cancels) builds each body as a pair with a rigid counterpart (the pair's
blocks are the sum of the bodies'), with the same coupling as the solved
pair. Half-plane displacements are relative to the model's datum (the log
kernel's reference length: a rigid shift in 2D). The BEM bodies (half-space
blocks, layers, finite cylinders) are
:func:`rolling_cli.influence.build.deformable_body`, the
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


def _elastic_halfplanes(case, pair, p_n: np.ndarray, p_t: np.ndarray) -> dict | None:
    """Elastic closed-form half-planes from the solved pair's blocks ``pair`` (``S_nn``, ``S_nt``: the
    pair's k L and C Sg, k = sum of the bodies' 2 (1 - nu^2) / (pi E), C = c_A - c_B the cross
    compliances, :mod:`.halfplane`), no kernel integrated again: body X's blocks are k_X L and c_X Sg,
    so L and Sg are the pair's divided by k and C. None where the pair's coupling is on but C = 0
    (Sg is then not in the pair: the caller integrates it)."""
    from ..model import materials as constants

    direct, cross = {}, {}
    for label in ("A", "B"):
        found = material(getattr(case.bodies, label))
        if found is not None:
            direct[label] = 2.0 * constants.plane_strain_compliance(found.young, found.poisson) / np.pi
            cross[label] = constants.coupling_compliance(found.young, found.poisson)
    k = sum(direct.values())
    big_c = cross.get("A", 0.0) - cross.get("B", 0.0)
    if pair.S_nt is not None and big_c == 0.0:
        return None
    log_n, log_t = _apply(pair.S_nn, p_n) / k, _apply(pair.S_nn, p_t) / k  # L p_n, L p_t
    sign_n = sign_t = np.zeros_like(p_n)  # Sg p_n, Sg p_t (zero: the coupling was not solved)
    if pair.S_nt is not None:
        sign_n, sign_t = _apply(pair.S_nt, p_n) / big_c, _apply(pair.S_nt, p_t) / big_c
    out = {}
    for label, k_x in direct.items():
        side = 1.0 if label == "A" else -1.0  # the body's tangential traction, +-p_t
        c_x = cross[label]
        out[label] = (k_x * log_n + side * c_x * sign_t, c_x * sign_n - side * k_x * log_t)
    return out


def body_displacements(
    case, the_plan, p_n: np.ndarray, p_t: np.ndarray, pair=None
) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """{label: (w, u)} [length] of each deformable body of ``case`` ("A", "B"; a rigid one is left out)
    for the nodal tractions ``p_n``, ``p_t`` [stress] on the plan's contact grid (p_t on A).
    ``pair``: the solved pair's blocks (``S_nn``, ``S_nt``, e.g. the contact system), which serve
    elastic closed-form half-planes without integrating their kernels again. Empty when the tractions
    are not on the plan's grid (a system built on another grid: the bodies' blocks are not at hand)."""
    elastic_halfplane = the_plan.effects.influence == "half-plane" and not viscoelastic_bodies(case)
    if pair is not None and elastic_halfplane:
        found = _elastic_halfplanes(case, pair, p_n, p_t)
        if found is not None:
            return found
    grid_x = the_plan.grid.x
    if grid_x.shape != p_n.shape or (pair is not None and not np.array_equal(grid_x, pair.x)):
        return {}  # solved on another grid than the plan's (pipeline.explicit): no body blocks to apply
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

        own, _ = deformable_body(case, the_plan, body, use_cache=False)  # in memory; never the disk cache
        traction = p_t if label == "A" else -p_t
        # the cross blocks where the solve had them; a finite body's always (its pair's gap and the
        # power balance take all four, :func:`rolling_cli.influence.finite.finite_pair`)
        coupled = the_plan.effects.coupling or body.finite
        w = _apply(own.S_nn, p_n) + _apply(own.S_nt if coupled else None, traction)
        u = _apply(own.S_tn if coupled else None, p_n) + _apply(own.S_tt, traction)
        out[label] = (w, u)
    return out
