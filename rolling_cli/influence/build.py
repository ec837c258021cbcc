"""Choose and build the influence model of a planned case.

* ``half-plane``: the closed form of :mod:`.halfplane` for the pair, with the
  coupling blocks only when the effects call for them.
* ``bem``: one BEM condensation per distinct deformable body (:mod:`.bem`),
  combined with :func:`rolling_cli.influence.combine`.

Results are memoised in-process on everything they depend on, so sweeps that
change only friction or loads never rebuild them.
"""

from __future__ import annotations

import functools

from . import Compliance, halfplane


def pair_compliance(case, the_plan) -> Compliance:
    """The pair compliance on the plan's contact grid [length/stress]."""
    a, b = case.bodies.A, case.bodies.B
    coupling = the_plan.effects.coupling
    if case.discretization.influence == "half-plane":
        return _halfplane(the_plan.grid, a.modulus, a.ratio, b.modulus, b.ratio, coupling)
    raise NotImplementedError("the BEM influence model is not built yet")


@functools.lru_cache(maxsize=8)
def _halfplane(grid, young_a, poisson_a, young_b, poisson_b, coupling) -> Compliance:
    return halfplane.pair_compliance(grid, young_a, poisson_a, young_b, poisson_b, coupling)
