"""One continuation driver for every path the solver walks.

A path is a parameter s and a list of converged points [(s_k, solution_k)].
:func:`follow` walks to each target value in turn: it asks ``predict(points,
s)`` for a start (a secant over the last two points, or a transfer onto a new
grid), solves there with ``solve_at(s, start)``, and on failure halves the step
towards the target (inserting intermediate points) when the parameter is
continuous. After an easy success (few Newton iterations) the next step grows.

Paths walked with it: the coupling scale from 0 to 1 (strategies), a sweep's or
a creep-force curve's swept value (:mod:`rolling_cli.study.sweep`), and the mesh
levels of a solve (coarse grid, larger zone: :mod:`rolling_cli.pipeline`),
whose parameter is discrete (``control=None``: no halving).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

from .budget import Budget


@dataclass(frozen=True)
class StepControl:
    """Step-size control of a continuous path.

    The step halves after a failure (down to ``min_fraction`` of the distance
    between two targets) and doubles, up to the distance to the target, after
    a success within ``easy`` Newton iterations.
    """

    shrink: float = 0.5
    grow: float = 2.0
    easy: int = 3
    min_fraction: float = 1.0 / 64.0


class ContinuationFailed(Exception):
    """No point could be solved beyond ``parameter``; ``best`` the last solution (or None)."""

    def __init__(self, parameter: float, reason: str, best: Any, residual: float) -> None:
        self.parameter = parameter
        self.reason = reason
        self.best = best
        self.residual = residual
        super().__init__(f"continuation stopped at {parameter:.6g}: {reason}")


def follow(
    targets: Iterable[float],
    solve_at: Callable[[float, Any], tuple[Any, int]],
    predict: Callable[[list, float], Any],
    points: list,
    *,
    failure: type[Exception] | tuple[type[Exception], ...],
    control: StepControl | None = None,
    budget: Budget | None = None,
) -> list:
    """Walk from ``points[-1]`` through each target; append every converged point to ``points``.

    ``solve_at(s, start)`` returns (solution, Newton iterations) or raises
    ``failure``, an exception with attributes ``residual`` and ``reason`` (a
    failed strategy). ``targets`` may be a generator that looks at ``points`` to decide
    the next target (a re-mesh event). Returns ``points``.
    """
    step = None
    for target in targets:
        s = points[-1][0]
        distance = target - s
        if step is None or control is None:
            step = distance
        step = min(abs(step), abs(distance)) * (1.0 if distance >= 0 else -1.0)
        smallest = abs(distance) * control.min_fraction if control else abs(distance)
        while True:
            s = points[-1][0]
            if s == target:
                break
            trial = target if abs(target - s) <= abs(step) * (1.0 + 1e-12) else s + step
            try:
                solution, iterations = solve_at(trial, predict(points, trial))
            except failure as err:
                if control is None or abs(step) * control.shrink < smallest or (budget and budget.exhausted):
                    reason, residual = getattr(err, "reason", str(err)), getattr(err, "residual", float("nan"))
                    raise ContinuationFailed(trial, reason, points[-1][1], residual) from err
                step *= control.shrink
                continue
            points.append((trial, solution))
            if control is not None and iterations <= control.easy:
                step *= control.grow
    return points
