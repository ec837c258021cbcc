"""Is a solved case inside the validity of its model? (the half-space assumption)

Both influence models treat each body near the contact as a half-space (or,
for a layer, a flat strip) loaded on a flat boundary, with small-strain linear
elasticity and the parabolic profile x^2 / (2 R). That holds when the contact
half-width a is small against every curved body's radius R. The neglected
terms grow with a/R:

* the surface's slope at the contact edge, a/R rad, which the flat boundary
  ignores (the normal and tangential directions turn by it);
* the strain, p0/E* = a/(2 R*) for Hertz, which small-strain elasticity needs
  small;
* the profile: a circle's gap exceeds the parabola by (a/R)^2 / 4 relatively
  at the contact edge.

:data:`HALF_SPACE_LIMIT` = 0.1 keeps the slope below 0.1 rad (6 degrees), the
strain below 5 % and the profile error at 0.25 %, the usual engineering
reading of "a << R" for Hertzian theory; beyond it the result is still the
exact solution of the model, but the model is not the cylinders.
"""

from __future__ import annotations

import math

#: Largest contact half-width over radius (a/R) for which the half-space model is trusted.
HALF_SPACE_LIMIT = 0.1


def half_space_check(case, half_width: float) -> dict:
    """Result attributes: ``half_space_ratio`` = a / R of the most curved body [-]
    (NaN without contact or with two flats) and ``validity_warning`` (empty when
    a/R <= :data:`HALF_SPACE_LIMIT`). ``half_width`` is the solved a [length].
    """
    label, radius = min(
        (("A", float(case.bodies.A.radius)), ("B", float(case.bodies.B.radius))), key=lambda item: item[1]
    )
    ratio = half_width / radius if math.isfinite(radius) and half_width > 0.0 else math.nan
    warning = ""
    finite = case.bodies.A.shape == "cylinder" or case.bodies.B.shape == "cylinder"  # exact geometry: no half-space
    if ratio > HALF_SPACE_LIMIT and not finite:
        warning = (
            f"a/R = {ratio:.3g} > {HALF_SPACE_LIMIT:g} (contact half-width {half_width:.4g} against "
            f"bodies.{label}.radius = {radius:.4g}): the half-space model and small strains do not hold, "
            "so this result does not describe the cylinders"
        )
        if not getattr(case.bodies, label).rigid:  # the finite model exists for this body
            warning += (
                f'; shape = "cylinder" under [bodies.{label}] models its whole cross-section (the half-space '
                f"creepage error here is about {0.7 * ratio:.2g} mu a/R for a solid roller: README, error map)"
            )
    return {"half_space_ratio": ratio, "validity_warning": warning}
