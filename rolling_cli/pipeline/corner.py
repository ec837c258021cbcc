"""The strongly coupled corner's mesh rules (mu |beta_Dundurs| above 1, issue 23): the potential
zone, the iteration budget and the start of the creepage path (:mod:`rolling_cli.solver.corner`),
applied by the mesh path (:mod:`rolling_cli.pipeline.mesh_path`)."""

from __future__ import annotations

import dataclasses
import math

from ..case import Case, with_overrides
from ..solver import corner as corner_path
from ..solver.formulation import State
from ..solver.system import ContactSystem
from .planning import Level, Plan, initial_state

#: mu |beta_Dundurs| above which a coupled solve takes the zone of :data:`CORNER_ZONE`: the creepage
#: path's threshold. From 0.6 (the pipeline's "strong coupling" of its failure messages) it was
#: measured both ways: benchmarks/robustness.py's 2800 half-spaces (mu |beta| up to 0.75) took 24 %
#: fewer iterations, no failure either way, but issue 23's bodies at mu |beta| = 0.6 lost one of 21
#: creepages (xi = 0.0033; 20 of 21, 998 iterations against 21 and 751 on the 1.5 a zone).
ZONE_COUPLING = corner_path.STRONG


#: The same threshold under force control (any tangential control but the creepage), where it was
#: measured both ways without a loss: robustness.py part 1 (2800 half-spaces, 0 failures either
#: way; 23907 iterations against 31418 on the 1.5 a zone), and part 6's one corner failure of 16
#: (mu |beta| = 0.795, Q/(mu P) = 0.98: enlarged zones 2.25 and 3.375 a failed; on 2.5 a, 72
#: iterations). benchmarks/RESULTS.md, "the last failures".
FORCE_ZONE_COUPLING = 0.6


#: The potential zone / a of a strongly coupled case (mu |beta_Dundurs| above
#: :data:`ZONE_COUPLING`), at least: there the contact moves to one side as the
#: creepage grows (issue 23's case: from [-1.08, 0.73] a at xi = 0 to [-1.76, 0.53] a near full slip),
#: past the default 1.5 a; each enlarged zone was a new solve, and every iterate that touched the
#: edge of a failed one grew the zone again (benchmarks/RESULTS.md, the corner).
CORNER_ZONE = 2.5


#: A strongly coupled level under creepage control may take this many times solver.max_iterations:
#: a cold one's creepage path moves the stick/slip boundary about a node an iteration (issue 23's
#: case, 104 coarse elements: up to 248 iterations at xi = 0.04, each a dense solve of ~200 unknowns,
#: 0.5 s in all); a warm one may need its nudged creepages (solver/corner.py) after a failed Newton:
#: with :func:`~rolling_cli.solver.corner.warm_chain`, xi = 0.035 took 780 iterations of all levels
#: (issue 23's case, 417 elements; about 130 of them on the coarse grid).
CORNER_BUDGET = 6


def strongly_coupled(case: Case, the_plan: Plan, above: float = ZONE_COUPLING) -> bool:
    """mu |beta_Dundurs| above ``above`` in a coupled solve."""
    strength = abs(0.5 * the_plan.beta_seed) * case.friction.mu
    return the_plan.effects.strategy == "coupled" and strength > above


def corner_zone(case: Case, the_plan: Plan) -> Case:
    """``case`` on a zone of :data:`CORNER_ZONE` a at least when strongly coupled (above
    :data:`ZONE_COUPLING` under creepage control, :data:`FORCE_ZONE_COUPLING` else), with the same
    element length (as an enlarged zone); else ``case``."""
    disc = case.discretization
    above = ZONE_COUPLING if case.tangential.control()[0] == "creep" else FORCE_ZONE_COUPLING
    if not strongly_coupled(case, the_plan, above) or disc.zone >= CORNER_ZONE or disc.tolerance is not None:
        return case
    elements = int(math.ceil(disc.contact_elements * CORNER_ZONE / disc.zone - 1e-9))
    return dataclasses.replace(
        case, discretization=dataclasses.replace(disc, zone=CORNER_ZONE, contact_elements=elements)
    )


def corner_start(level: Level, system: ContactSystem) -> State | None:
    """For a level with mu |beta| above :data:`~rolling_cli.solver.corner.STRONG`, the closed-form
    start at xi = 0 (where :func:`~rolling_cli.solver.corner.creep_path` and, under force control,
    :func:`~rolling_cli.solver.corner.force_path` begin); else None."""
    if not strongly_coupled(level.case, level.plan, corner_path.STRONG):
        return None
    return initial_state(with_overrides(level.case, {"tangential.creep": 0.0}), level.plan, system)
