"""The adaptive mesh levels of a solve: accuracy on demand (``[discretization] tolerance``).

:class:`rolling_cli.pipeline.MeshPath` walks the mesh levels of a solve with
the continuation driver. With a tolerance, after the case's own grid (and any
enlarged zone) it asks :meth:`Adaptation.next_grid` for one more level at a
time, from the last solved one:

1. **the estimate** of the level's maximum traction error
   (:func:`.accuracy.estimate`: the traction jumps and the kink motion), as a
   fraction of mu p0 (of p0 when mu = 0). It was never below the true error
   over the study, so it is compared with the tolerance as it is, without a
   further safety factor (see :data:`SAFETY`);
2. **stop** when the estimate meets the tolerance; or, with a message naming
   the estimate reached: after ``discretization.max_refinements``
   refinements; when the estimate stops falling (:data:`STALL`: the estimate
   cannot certify the request, the result says "NOT certified" with the
   estimate reached; the true error may be below the request, as the
   estimate is a bound several times above it, and the smallest elements may
   be at their round-off floor); when the next mesh would exceed :attr:`Adaptation.max_elements`
   (:data:`MAX_ELEMENTS`, on the BEM :data:`MAX_BEM_ELEMENTS`) or the memory
   available;
3. **the next grid**, on either influence model (the half-plane's closed form
   or the BEM, whose body meshes take the graded contact elements): a grid
   graded towards the located kinks (contact edges, stick/slip boundaries)
   with the indicator's element-length field elsewhere, elements far below
   the target allowed to grow (:func:`.remesh.next_grid`), none longer than
   :attr:`Adaptation.largest` (a layer's rule: at most half its thickness);
4. **the start** of the new level: the last solution moved onto the new grid
   (:func:`transferred_state`), or the closed-form (Hertz, Carter) start
   when that has the smaller residual (the pipeline compares the two).

No solves here: the decisions on plain arrays, and a small record of the run.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..model.grid import ContactGrid
from ..solver.formulation import State
from . import accuracy, kinks, remesh, transfer
from .accuracy import LevelFields

#: Fraction of the tolerance the next mesh aims at (remesh.SAFETY): the refined elements ask for
#: h (SAFETY tolerance / eta)^2, so one refinement usually suffices near a kink. The STOPPING test
#: uses the estimate itself against the tolerance: the estimate was 2.2 to 59 times the true error
#: over the study, so a further factor would only buy more elements.
SAFETY = remesh.SAFETY
#: The estimate must fall below this fraction of the best earlier one within :data:`STALL_LEVELS`
#: refinements, or the loop stops (the estimate cannot certify the tolerance).
STALL = 0.8
STALL_LEVELS = 2
#: Most contact elements of an adaptive level (a dense half-plane level of 4000 elements holds
#: about 1 GB of influence and takes tens of seconds; the BEM far more).
MAX_ELEMENTS = 4000
#: Graded levels: elements away from the kinks, whose indicator is below the target, may grow by
#: this factor per level, up to the zone over FEWEST_ELEMENTS (a fine uniform start, such as the
#: default 200 elements, then does not stay fine where the traction is smooth).
COARSEN = 2.0
FEWEST_ELEMENTS = 20
#: Most contact elements of a BEM level: the BEM build of 1280 contact elements takes about a
#: minute on 2 cores (640: 12 s, growing like N^2.5; benchmarks/results/accuracy_cost.md).
MAX_BEM_ELEMENTS = 1280

GRADED = "graded towards the kinks"

#: What an estimate on a finite cylinder leaves out (appended to ``adaptive_method``): it reads the
#: contact tractions' kinks only, while the body's own mesh away from the contact (graded by distance,
#: :mod:`rolling_cli.influence.bem.cylinder`) is fixed; its error is measured separately (README).
FINITE_BODY_SCOPE = "; contact discretisation only (the finite body's mesh away from the contact is not estimated)"


@dataclass
class Adaptation:
    """The progress of one adaptive solve: the request, every level's estimate, and why it stopped.

    ``tolerance`` [-] (a fraction of mu p0, of p0 when frictionless),
    ``max_refinements``, ``largest`` the longest contact element allowed
    [length] (a layer's rule; None: no rule beyond the zone over
    :data:`FEWEST_ELEMENTS`), ``max_elements`` the most contact elements of a
    level, ``fits(elements) -> str`` says why a level of that many elements
    cannot be solved ("" when it can: the memory check).
    """

    tolerance: float
    max_refinements: int
    largest: float | None = None
    max_elements: int = MAX_ELEMENTS
    fits: Callable[[int], str] | None = None
    history: list[dict] = field(default_factory=list)
    note: str = ""
    met: bool = False
    kinks: tuple | None = None

    @property
    def refinements(self) -> int:
        """Levels solved after the first estimated one."""
        return max(len(self.history) - 1, 0)

    @property
    def estimate(self) -> float:
        """The estimate of the last solved level [-] (NaN before any)."""
        return self.history[-1]["estimate"] if self.history else math.nan

    def next_grid(self, level: LevelFields) -> ContactGrid | None:
        """Record ``level``'s estimate; the grid of the next level, or None when the loop stops
        (the tolerance is met, or a cap is reached: :attr:`note` says which)."""
        found = accuracy.estimate(level, self.kinks)
        self.kinks = (found.positions, found.kinds)
        estimate = found.value
        self.history.append(
            {
                "elements": level.grid.elements,
                "estimate": estimate,
                "jumps": found.jumps,
                "kink_motion": found.motion,
                "creep": level.creep,
                "iterations": level.iterations,
                "seconds": level.seconds,
            }
        )
        if estimate <= self.tolerance:
            self.met, self.note = True, ""
            return None
        reached = f"estimate {estimate:.3g} at {level.grid.elements} contact elements"
        if self.refinements >= self.max_refinements:
            self.note = (
                f"tolerance {self.tolerance:g} not met: {reached} after {self.refinements} refinements "
                f"(discretization.max_refinements = {self.max_refinements})"
            )
            return None
        new = self._graded(level, found)
        if new is None:
            return None
        refused = f"more than the {self.max_elements} allowed" if new.elements > self.max_elements else ""
        if not refused and self.fits is not None:
            refused = self.fits(new.elements)
        if refused:
            self.note = (
                f"tolerance {self.tolerance:g} not met: {reached}; the next mesh would need {new.elements} "
                f"contact elements, {refused}"
            )
            return None
        return new

    def _graded(self, level: LevelFields, found: accuracy.Estimate) -> ContactGrid | None:
        """The next graded grid (:func:`.remesh.next_grid`), or None (and :func:`stall_note`) when
        the estimate has stopped falling."""
        if self.stalled():
            earlier = min(row["estimate"] for row in self.history[:-STALL_LEVELS])
            self.note = stall_note(self.tolerance, found.value, earlier, self.refinements, level.grid.elements)
            return None
        largest = 2.0 * level.grid.half_width / FEWEST_ELEMENTS
        if self.largest is not None:
            largest = min(largest, self.largest)
        return remesh.next_grid(
            level.grid,
            found.eta,
            found.positions,
            found.kinds,
            self.tolerance,
            SAFETY,
            coarsen=COARSEN,
            largest=largest,
        )

    def stalled(self) -> bool:
        """The estimate has not fallen below :data:`STALL` times the best earlier one for
        :data:`STALL_LEVELS` refinements."""
        if len(self.history) <= STALL_LEVELS:
            return False
        recent = min(row["estimate"] for row in self.history[-STALL_LEVELS:])
        earlier = min(row["estimate"] for row in self.history[:-STALL_LEVELS])
        return recent > STALL * earlier

    def attributes(self, grid: ContactGrid) -> dict:
        """Result attributes of the run, the final ``grid``'s element edges [length] among them."""
        creep = [row["creep"] for row in self.history]
        change = abs(creep[-1] - creep[-2]) / abs(creep[-1]) if len(creep) > 1 and creep[-1] else math.nan
        return {
            "adaptive_tolerance": self.tolerance,
            "adaptive_estimate": self.estimate,
            "adaptive_met": self.met,
            "adaptive_refinements": self.refinements,
            "adaptive_method": GRADED,
            "adaptive_note": self.note,
            "adaptive_creep_change": change,
            "adaptive_history": json.dumps(self.history),
            "element_edges": np.asarray(grid.edges, dtype=float),
            "element_order": grid.order,
        }


def stall_note(tolerance: float, estimate: float, earlier: float, refinements: int, elements: int) -> str:
    """The note of a loop stopped because the estimate stopped falling (all arguments dimensionless).

    Says that the estimate cannot certify the request and what it reached, not
    that the model cannot resolve it: the estimate is a bound (:data:`SAFETY`'s
    study: 2.2 to 59 times the true error), and on Carter's case at
    Q/(mu P) = 0.98 it stalls at 1.4e-4 with the true error 9e-6.
    """
    return (
        f"tolerance {tolerance:g} NOT certified: the error estimate stalled at {estimate:.3g} after {refinements} "
        f"refinements ({elements} contact elements; best {earlier:.3g} {STALL_LEVELS} refinements earlier) and "
        "cannot certify a smaller error; being a bound (2 to 60 times the true error where measured), it does not "
        f"mean that the true error exceeds {tolerance:g}. To try: a tolerance of at least {estimate:.3g} is "
        "certified on these meshes; adaptive_history shows how the creepage settled over the levels"
    )


def transferred_state(level: LevelFields, new: ContactGrid) -> State:
    """The solution of ``level`` moved onto ``new`` (same zone): tractions by the old elements'
    interpolants, the pressure ending like a square root at the located contact edges and the
    traction within the friction bound (:func:`.transfer.transfer_tractions`); overlap and
    creepage kept."""
    edges = kinks.contact_edges(level.grid.x, level.p_n, level.gap)
    p_n, p_t = transfer.transfer_tractions(level.grid, level.p_n, level.p_t, level.mu, new, edges)
    return State(p_n, p_t, float(level.overlap), float(level.creep))


def summary_line(attrs: Mapping[str, Any]) -> str | None:
    """The summary's line for an adaptive result (None for a fixed mesh)."""
    if "adaptive_tolerance" not in attrs:
        return None
    status = "met" if attrs.get("adaptive_met") else "NOT met"
    if "NOT certified" in str(attrs.get("adaptive_note", "")):
        status = "NOT certified"  # the estimate stalled (stall_note)
    # files written before the BEM took graded grids may say "uniform refinement"
    method = "graded" if str(attrs.get("adaptive_method", "")).startswith("graded") else "uniform refinement"
    scope = "; contact discretisation only" if str(attrs.get("adaptive_method", "")).endswith(FINITE_BODY_SCOPE) else ""
    return (
        f"  accuracy       tolerance {attrs['adaptive_tolerance']:g} {status}: estimate "
        f"{attrs['adaptive_estimate']:.3g} (of mu p0; p0 when frictionless), {attrs.get('contact_elements')} "
        f"elements after {attrs.get('adaptive_refinements')} refinements ({method}{scope})"
    )
