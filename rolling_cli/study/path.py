"""Warm-started paths through neighbouring cases: sweeps and creep-force curves.

A :class:`CasePath` solves cases one after the other on one contact system.
Each case starts from the boundary-tracking secant prediction of its two
predecessors (:func:`rolling_cli.solver.predictor.secant`) when the swept values
lie on a line, else from its predecessor's solution or the closed-form cold
start, whichever has the smaller residual. The path parameter is the distance
along that line; when a case fails from its prediction, the continuation
driver (:func:`rolling_cli.solver.continuation.follow`) halves the step by
solving intermediate cases (numeric keys only) before it gives up.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import pipeline
from ..case import Case, with_overrides
from ..errors import RollingError
from ..pipeline.branches import result_state
from ..result import Result, recorded
from ..solver import continuation, predictor
from ..solver.system import ContactSystem


def result_zones(result: Result) -> predictor.Zones:
    """Zone pattern and boundaries of a result (for the secant predictor)."""
    labels = predictor.node_labels(result.p_n, result.p_t, result.state == 1)
    return predictor.zones(result.x, labels, result.p_n, result.p_t, recorded(result.mu, "mu") * np.abs(result.p_n))


class _CaseFailed(Exception):
    def __init__(self, error: RollingError) -> None:
        self.error = error
        self.reason = str(error)
        self.residual = getattr(error, "residual", None) or math.nan
        super().__init__(self.reason)


@dataclass
class _Point:
    values: dict
    result: Result


def _numeric(values: dict) -> np.ndarray | None:
    if not values or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values.values()):
        return None
    return np.array([float(v) for v in values.values()])


class CasePath:
    """Solve neighbouring cases on one contact system, each warm-started from its predecessors."""

    def __init__(self, system: ContactSystem, warm: bool = True, use_cache: bool = True) -> None:
        self.system = system
        self.warm = warm
        self.use_cache = use_cache
        self.points: list[_Point] = []

    def solve(self, case: Case, values: dict) -> Result:
        """Solve ``case`` (with swept ``values``), extending the path; raises RollingError on failure."""
        if not self.warm or not self.points:
            result = pipeline.solve(case, system=self.system, use_cache=self.use_cache)
        else:
            result = self._follow(case, values)
        self._extend(values, result)
        return result

    def _extend(self, values: dict, result: Result) -> None:
        same_grid = result.x.shape == self.system.x.shape and bool(np.array_equal(result.x, self.system.x))
        if not same_grid:  # the zone grew: neighbours on the old grid no longer predict this one
            self.points = []
            return
        self.points = [*self.points[-1:], _Point(values, result)]

    def _segment(self, values: dict) -> tuple[np.ndarray | None, list[float]]:
        """The step from the last point to ``values``, and the path parameters of the earlier points that
        lie on the same line (the last point at 0, the target at 1)."""
        here = _numeric(values)
        last = _numeric(self.points[-1].values)
        if here is None or last is None or here.shape != last.shape:
            return None, []
        step = here - last
        length = float(np.linalg.norm(step))
        earlier: list[float] = []
        for point in reversed(self.points[:-1]):
            before = _numeric(point.values)
            if before is None or before.shape != last.shape or length == 0.0:
                break
            offset = before - last
            distance = float(np.linalg.norm(offset))
            if distance == 0.0 or float(offset @ step) > -(1.0 - 1e-9) * distance * length:
                break  # not on the line behind the last point
            earlier.insert(0, -distance / length)
        return step, earlier

    def _follow(self, case: Case, values: dict) -> Result:
        step, earlier = self._segment(values)
        last = self.points[-1]
        mu = case.friction.mu
        x = self.system.x
        # parameter s along the segment: the last point at 0, the target at 1
        behind = self.points[len(self.points) - 1 - len(earlier) : -1]
        points: list[tuple[float, Result]] = [(s, p.result) for s, p in zip(earlier, behind, strict=True)]
        points.append((0.0, last.result))
        keys = list(values)

        def case_at(s: float) -> Case:
            base = _numeric(last.values)
            if s == 1.0 or step is None or base is None:
                return case
            return with_overrides(case, dict(zip(keys, (base + s * step).tolist(), strict=True)))

        def predict(done, s):
            # a step's solution on an enlarged zone (another grid) predicts nothing here: the closed form
            # (a corner sweep crashed in the secant's interpolation when it used one)
            done = [(sk, r) for sk, r in done[-2:] if r.x.shape == x.shape]
            if not done:
                return None
            return predictor.secant(x, [(sk, result_state(r), result_zones(r)) for sk, r in done], s, mu)

        def solve_at(s, start):
            try:
                result = pipeline.solve(
                    case_at(s), start=start, system=self.system, use_cache=self.use_cache, compare_start=len(points) < 2
                )
            except RollingError as err:
                raise _CaseFailed(err) from None
            return result, int(result.iterations)

        control = continuation.StepControl(grow=1.0) if step is not None else None
        try:
            continuation.follow([1.0], solve_at, predict, points, failure=_CaseFailed, control=control)
        except continuation.ContinuationFailed as err:
            if not isinstance(err.__cause__, _CaseFailed):
                raise
            raise err.__cause__.error from None
        return points[-1][1]
