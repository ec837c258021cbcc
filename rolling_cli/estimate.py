"""A-posteriori error estimate: the same case re-solved on half the contact elements.

The difference between the two solutions, on the fine nodes, estimates the
discretisation error of the fine one: for a method converging like N^-p the
fine error is d / (2^p - 1), so d itself for p = 1, and about 2.4 d for the
p = 1/2 of square-root stick/slip kinks. How it compares with the true error
is measured in benchmarks/accuracy_cost.py (README, "What accuracy costs").
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .case import Case
from .errors import RollingError
from .pipeline import solve
from .result import Result


def half_mesh_case(case: Case) -> Case:
    """The case with half the contact elements (at least 2)."""
    disc = case.discretization
    return dataclasses.replace(
        case,
        discretization=dataclasses.replace(disc, contact_elements=max(2, disc.contact_elements // 2)),
        stresses=None,
    )


def add_error_estimate(case: Case, result: Result, use_cache: bool = True) -> Result:
    """Annotate ``result`` with the half-mesh differences (attributes ``error_estimate*``).

    * ``error_estimate``: max |p_t - p_t(half)| / (mu p0) over the fine nodes
      (p_n / p0 when frictionless);
    * ``error_estimate_rms``: its RMS over the contact;
    * ``error_estimate_creep``: |xi - xi(half)| / |xi| (0 when xi = 0);
    * ``error_estimate_load``: |P - P(half)| / P (overlap control);
    * ``error_estimate_elements``: the half mesh's element count.

    When the half mesh is not a valid discretisation (a layer needs elements
    no longer than b/2) or fails to solve, the estimate is NaN and
    ``error_estimate_note`` says why.
    """
    try:
        coarse = solve(half_mesh_case(case), use_cache=use_cache)
    except RollingError as err:
        attrs = result.attributes
        for key in ("error_estimate", "error_estimate_rms", "error_estimate_creep", "error_estimate_load"):
            attrs[key] = float("nan")
        attrs["error_estimate_elements"] = max(2, case.discretization.contact_elements // 2)
        attrs["error_estimate_note"] = f"no estimate: the half mesh cannot be solved ({err})"
        return result
    p0 = float(np.max(-result.p_n))
    mu = result.mu
    if mu > 0.0:
        fine, rough, scale = result.p_t, np.interp(result.x, coarse.x, coarse.p_t), mu * p0
    else:
        fine, rough, scale = result.p_n, np.interp(result.x, coarse.x, coarse.p_n), p0
    diff = np.abs(fine - rough) / scale
    contact = (result.p_n < 0.0) | (np.interp(result.x, coarse.x, coarse.p_n) < 0.0)
    attrs = result.attributes
    attrs["error_estimate"] = float(diff.max())
    attrs["error_estimate_rms"] = float(np.sqrt(np.mean(diff[contact] ** 2))) if contact.any() else 0.0
    attrs["error_estimate_creep"] = abs(result.creep - coarse.creep) / abs(result.creep) if result.creep else 0.0
    attrs["error_estimate_load"] = abs(result.normal_load - coarse.normal_load) / result.normal_load
    attrs["error_estimate_elements"] = coarse.contact_elements
    return result
