"""A-posteriori error estimate: the same case re-solved on half (or twice) the contact elements.

The difference d between the two solutions, on this result's nodes, estimates
the discretisation error of this result. For a method converging like N^-p:

* **half mesh** (the default): this result's error is d / (2^p - 1), so d
  itself for p = 1, and about 2.4 d for the p = 1/2 of square-root stick/slip
  kinks;
* **refined mesh**, used when the half mesh is not a valid discretisation (a
  layer needs contact elements no longer than b/2, so halving its minimum
  mesh is not allowed): this result's error is d 2^p / (2^p - 1), reported
  for p = 1/2 (the square-root kinks that set the maximum error), 3.41 d.
  With p = 1 (2 d) the tyred case's estimate fell below its true error at
  60 elements (0.8 times; benchmarks/results/accuracy_cost.md).

How the estimate compares with the true error is measured in
benchmarks/accuracy_cost.py (README, "What accuracy costs").
"""

from __future__ import annotations

import dataclasses
import logging

import numpy as np

from ..case import Case
from ..errors import CaseError, RollingError
from ..result import Result, recorded
from . import solve

log = logging.getLogger(__name__)

#: Error of this result per difference to the refined mesh: 2^p / (2^p - 1) for p = 1/2.
REFINED_FACTOR = 2.0**0.5 / (2.0**0.5 - 1.0)

_KEYS = ("error_estimate", "error_estimate_rms", "error_estimate_creep", "error_estimate_load")


def with_elements(case: Case, elements: int) -> Case:
    """The case with ``elements`` contact elements on the fixed mesh (no adaptive levels)."""
    disc = dataclasses.replace(case.discretization, contact_elements=elements, tolerance=None)
    return dataclasses.replace(case, discretization=disc, stresses=None)


def add_error_estimate(case: Case, result: Result, use_cache: bool = True) -> Result:
    """Annotate ``result`` with the mesh-comparison estimates (attributes ``error_estimate*``).

    * ``error_estimate``: max |p_t - p_t(other)| / (mu p0) over this result's
      nodes (p_n / p0 when frictionless);
    * ``error_estimate_rms``: its RMS over the contact;
    * ``error_estimate_creep``: |xi - xi(other)| / |xi| (0 when xi = 0);
    * ``error_estimate_load``: |P - P(other)| / P (overlap control);
    * ``error_estimate_elements``: the other mesh's element count;
    * ``error_estimate_method``: "half mesh", or "refined mesh, ..." when
      halving breaks a mesh rule (a layer's contact elements must be at most
      b/2 long); the refined differences are scaled by :data:`REFINED_FACTOR`
      (module docstring).

    When neither mesh can be solved the estimates are NaN and
    ``error_estimate_note`` says why. An adaptive result (``discretization.tolerance``)
    already carries its estimate, the largest traction jump of its final mesh
    (``adaptive_estimate``): it is reported as ``error_estimate`` without a re-solve.
    """
    if "adaptive_estimate" in result.attributes:
        return _adaptive_estimate(result)
    elements = case.discretization.contact_elements
    other, method, factor = max(2, elements // 2), "half mesh", 1.0
    try:
        try:
            comparison = solve(with_elements(case, other), use_cache=use_cache)
        except CaseError as err:  # the half mesh breaks a mesh rule (a layer's b/2): refine instead
            log.info("error estimate: refining, as the half mesh is not allowed (%s)", err)
            other, factor = 2 * elements, REFINED_FACTOR
            method = "refined mesh, differences x 3.41 (the half mesh breaks a mesh rule)"
            comparison = solve(with_elements(case, other), use_cache=use_cache)
    except RollingError as err:
        attrs = result.attributes
        for key in _KEYS:
            attrs[key] = float("nan")
        attrs["error_estimate_elements"] = other
        attrs["error_estimate_method"] = method
        attrs["error_estimate_note"] = f"no estimate: the {method.split(',')[0]} cannot be solved ({err})"
        return result
    p0 = float(np.max(-result.p_n))
    mu = recorded(result.mu, "mu")
    if mu > 0.0:
        fine, rough, scale = result.p_t, np.interp(result.x, comparison.x, comparison.p_t), mu * p0
    else:
        fine, rough, scale = result.p_n, np.interp(result.x, comparison.x, comparison.p_n), p0
    diff = factor * np.abs(fine - rough) / scale
    contact = (result.p_n < 0.0) | (np.interp(result.x, comparison.x, comparison.p_n) < 0.0)
    attrs = result.attributes
    attrs["error_estimate"] = float(diff.max())
    attrs["error_estimate_rms"] = float(np.sqrt(np.mean(diff[contact] ** 2))) if contact.any() else 0.0
    xi, xi_other = recorded(result.creep, "creep"), recorded(comparison.creep, "creep")
    load, load_other = recorded(result.normal_load, "normal_load"), recorded(comparison.normal_load, "normal_load")
    creep = factor * abs(xi - xi_other)
    attrs["error_estimate_creep"] = creep / abs(xi) if xi else 0.0
    attrs["error_estimate_load"] = factor * abs(load - load_other) / load
    attrs["error_estimate_elements"] = comparison.contact_elements
    attrs["error_estimate_method"] = method
    return result


def _adaptive_estimate(result: Result) -> Result:
    """The adaptive result's own estimate as the ``error_estimate*`` attributes (module docstring)."""
    attrs = result.attributes
    for key in _KEYS:
        attrs[key] = float("nan")
    attrs["error_estimate"] = float(attrs["adaptive_estimate"])
    attrs["error_estimate_elements"] = attrs.get("contact_elements")
    attrs["error_estimate_method"] = "adaptive mesh: the largest traction jump"
    attrs["error_estimate_note"] = (
        f"adaptive mesh: {attrs['error_estimate']:.3g} of mu p0, its accuracy estimate (the largest traction "
        "jump); no mesh comparison"
    )
    return result
