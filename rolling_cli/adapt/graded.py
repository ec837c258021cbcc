"""The contact system of a graded adaptive level (half-plane model): its influence and its rounding floor."""

from __future__ import annotations

import numpy as np

from ..influence import halfplane
from ..model.viscoelastic import material


def graded_compliance(case, the_plan):
    """The half-plane pair compliance of ``case``'s bodies on ``the_plan``'s (graded) grid
    [length/stress], built outside the in-process influence memo (which would keep every
    level's dense matrices).

    Raises ValueError when the plan's model is not the half-plane: a BEM body on a graded grid is
    built by :func:`rolling_cli.influence.build.pair_compliance` (keyed on the grid's edges).
    """
    effects = the_plan.effects
    if effects.influence != "half-plane":
        raise ValueError("graded_compliance builds the half-plane model; the BEM's goes through influence.build")
    a, b = case.bodies.A, case.bodies.B
    return halfplane.materials_pair(the_plan.grid, material(a), material(b), effects.coupling)


def difference_roundoff(system, mu: float) -> float:
    """The relative residual [-] that rounding leaves in the slip rows of a graded grid's system.

    A slip row differences two displacement rows over the node distance h_i,
    (u_i - u_up) / h_i, and each u is a sum over every node of the log kernel (no
    decay), so its rounding error is about eps (sum_j |S_ij| + sum_j |S_up,j|) |p| / h_i.
    The solver's own floor (:func:`rolling_cli.solver.formulation.roundoff_floor`) takes
    row sums of the differenced matrices, which hide that cancellation: on a uniform
    grid h is never small enough for it to matter, on a grid graded to 1e-8 a it does
    (measured: the coupled Newton stalls at relative residuals of 1e-8 to 1e-7, its
    node states flickering, on the dissimilar case's finest levels). In units of
    the residual (penalty r_t times slip, over s_t = mu s_n), with |p_t| <= mu s_n
    and |p_n| <= s_n: r_t eps max_i (sum|S_tt| + sum|S_tn| / mu)_(i, up) / h_i. The
    half-plane's S_tt is -S_nn and its S_tn the system's S_nt. A worst case (every
    |p| at its maximum), so no further factor is applied.
    """
    eps = np.finfo(float).eps
    rows = np.abs(system.S_nn).sum(axis=1)
    if system.S_nt is not None and mu > 0.0:
        rows = rows + np.abs(system.S_nt).sum(axis=1) / mu
    gaps = np.diff(system.x)
    pair = rows[:-1] + rows[1:]  # a slip row and its upstream neighbour, either direction
    return float(system.reference_penalty_t * eps * np.max(pair / gaps)) if gaps.size else 0.0
