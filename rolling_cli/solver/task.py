"""What a solution strategy is given and gives back: the controls of a solve, the :class:`Task`
(system, mu, controls, tolerance, formulation, friction law), the :class:`Solution` and the
:class:`StrategyFailed` exception (:mod:`rolling_cli.solver.strategies` runs them)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..model.friction import SlipFriction
from . import predictor
from .formulation import Evaluation, Problem, State
from .system import ContactSystem

TANGENTIAL_KINDS = ("creep", "load", "q_over_p", "q_over_mu_p", "none")


@dataclass(frozen=True)
class Controls:
    """What is prescribed.

    ``load`` P [force/length] or ``overlap`` [length] (exactly one);
    ``tangential`` is (kind, value) with kind in :data:`TANGENTIAL_KINDS`:
    creepage xi [-], Q [force/length], Q/P [-], Q/(mu P) [-], or "none" (p_t = 0).
    """

    load: float | None
    overlap: float | None
    tangential: tuple[str, float]

    @property
    def force(self) -> tuple[str, float] | None:
        """The prescribed tangential force, or None (creepage prescribed or nothing tangential)."""
        kind, value = self.tangential
        return None if kind in ("creep", "none") else (kind, value)


@dataclass(frozen=True)
class Task:
    """One steady rolling solve: the contact system, mu, the controls, the relative tolerance and
    the formulation the effects call for ("coupled", "decoupled" or "normal"); ``friction`` a
    velocity-dependent law (``mu`` is then its mu_static) or None (Coulomb)."""

    system: ContactSystem
    mu: float
    controls: Controls
    tolerance: float
    formulation: str
    friction: SlipFriction | None = None

    def problem(self, mode: str, force: bool = True, system: ContactSystem | None = None) -> Problem:
        """The :class:`Problem` of one stage (``force=False`` holds the creepage)."""
        return Problem(
            system or self.system,
            mode,
            self.mu,
            self.controls.load,
            self.controls.force if force else None,
            self.friction,
        )

    @property
    def full_mode(self) -> str:
        """The mode whose residual measures the whole task."""
        return {"coupled": "coupled", "normal": "normal"}.get(self.formulation, "tangential")

    def prepared(self, state: State) -> State:
        """``state`` with the prescribed overlap or creepage imposed."""
        out = state.copy()
        if self.controls.overlap is not None:
            out.overlap = self.controls.overlap
        kind, value = self.controls.tangential
        if kind == "creep":
            out.creep = value
        elif kind == "none":
            out.creep = 0.0
        return out


@dataclass
class Solution:
    """A converged state, its evaluation (node states, residual) and the stage problem it solved."""

    state: State
    evaluation: Evaluation
    problem: Problem

    @property
    def stick(self) -> np.ndarray:
        """Adhesion nodes."""
        return self.evaluation.stick

    def zones(self) -> predictor.Zones:
        """Zone pattern and boundaries (for the continuation predictor)."""
        s = self.state
        labels = predictor.node_labels(s.p_n, s.p_t, self.evaluation.stick)
        return predictor.zones(self.problem.system.x, labels, s.p_n, s.p_t, self.problem.mu * np.abs(s.p_n))


class StrategyFailed(Exception):
    """A strategy did not converge. ``best`` is the best state it reached (or None), ``residual``
    its relative residual; ``stage`` names where it failed; ``causes`` collects the failures
    of combined strategies."""

    def __init__(
        self, strategy: str, stage: str, reason: str, best: State | None, residual: float, causes: list | None = None
    ) -> None:
        self.strategy = strategy
        self.stage = stage
        self.reason = reason
        self.best = best
        self.residual = residual
        self.causes = causes or []
        super().__init__(f"{strategy} ({stage}): {reason}, relative residual {residual:.3e}")


Strategy = Callable[..., Solution]
