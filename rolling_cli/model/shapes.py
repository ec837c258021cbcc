"""Body shapes: what part of a cylinder an influence model represents.

* :class:`HalfSpace` (the default): the body near its contact is a
  half-space, truncated far away (the closed-form half-plane or the BEM
  block). Valid while the contact is small against the radius (a/R < 0.1).
* :class:`Cylinder`: the whole cross-section, an annulus between
  ``inner_radius`` r_i and ``radius`` R, whose bore is bonded to a rigid shaft
  that carries the load and defines the body's rigid motion. A solid roller on
  an axle is a small bore; a covered roller (an elastic cover of thickness b
  on a rigid core) is the annulus with r_i = R - b (:func:`covered`).

The shapes are frozen values (hashable: cache keys); lengths in the case's
length unit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["BodyShape", "HalfSpace", "Cylinder", "covered", "SHAPES"]

#: The case-file names of the shapes (``[bodies.X] shape``).
SHAPES = ("half-space", "cylinder")


@dataclass(frozen=True)
class HalfSpace:
    """The body near its contact as a half-space (today's model)."""

    name: str = "half-space"

    def describe(self) -> str:
        """One phrase for the effects line."""
        return "half-space"


@dataclass(frozen=True)
class Cylinder:
    """An annulus r_i < r < R [length] bonded at r = r_i to a rigid shaft.

    ``radius`` R (finite, > 0); ``inner_radius`` r_i with 0 < r_i < R.
    """

    radius: float
    inner_radius: float
    name: str = "cylinder"

    def __post_init__(self) -> None:
        if not (math.isfinite(self.radius) and self.radius > 0.0):
            raise ValueError(f"a cylinder needs a finite positive radius, got {self.radius!r}")
        if not (0.0 < self.inner_radius < self.radius):
            raise ValueError(f"the inner radius must lie in (0, {self.radius:g}), got {self.inner_radius!r}")

    @property
    def thickness(self) -> float:
        """Radial thickness of the section R - r_i [length]."""
        return self.radius - self.inner_radius

    def describe(self) -> str:
        """One phrase for the effects line, e.g. ``finite cylinder (R = 5, bore 2)``."""
        return f"finite cylinder (R = {self.radius:g}, bore {self.inner_radius:g})"


def covered(radius: float, cover_thickness: float) -> Cylinder:
    """A cover of thickness b on a rigid core: the annulus R - b < r < R [length]."""
    return Cylinder(radius, radius - cover_thickness)


BodyShape = HalfSpace | Cylinder
