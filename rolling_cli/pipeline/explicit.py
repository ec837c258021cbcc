"""Solve a case on an explicit contact grid (graded or uniform) through :func:`rolling_cli.solve`.

The case fixes everything but the mesh: its plan (Hertz scale, zone, effects)
is kept and only the contact grid is replaced, so the influence is built on
the given element edges and the solver sees a prebuilt contact system. A
warm start (tractions on the new grid's nodes, overlap, creepage) can be
passed, for example the transfer of a coarser solution
(:func:`rolling_cli.adapt.transfer.transfer_tractions`).
"""

from __future__ import annotations

import dataclasses

from ..case import Case
from ..model.grid import ContactGrid
from ..result import Result
from ..solver.formulation import State
from ..solver.system import ContactSystem
from . import build_contact_system, measured_plan, solve


def system_on_grid(case: Case, grid: ContactGrid, use_cache: bool = True) -> ContactSystem:
    """The case's contact system with its contact grid replaced by ``grid`` (same zone).

    A graded grid's influence is built outside the in-process memo, which would otherwise
    keep the dense matrices of every level of an adaptive run: the half-plane's by
    :func:`rolling_cli.adapt.graded.graded_compliance`, a BEM body's keyed on the grid's
    edges in the disk cache (:func:`rolling_cli.influence.build.bem_inputs`).
    """
    the_plan = dataclasses.replace(measured_plan(case, use_cache), grid=grid)
    return build_contact_system(case, the_plan, use_cache)


def solve_on_grid(case: Case, grid: ContactGrid, start: State | None = None, use_cache: bool = True) -> Result:
    """:func:`rolling_cli.solve` of ``case`` on ``grid``; ``start`` a warm start on its nodes.

    The result's ``contact_elements`` attribute is the grid's element count.
    """
    result = solve(case, start=start, system=system_on_grid(case, grid, use_cache), use_cache=use_cache)
    result.attributes["contact_elements"] = grid.elements
    return result
