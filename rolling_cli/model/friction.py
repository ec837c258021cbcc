"""Friction laws: the coefficient of friction as a function of the absolute slip speed.

The slip speed is s_a = |V| |s_t| [length/time]: s_t is this project's slip
velocity normalised by the rolling speed |V| (dimensionless, like the
creepage), so a velocity-dependent law needs ``rolling.speed`` = |V|.

The forms are CONTACT's (Vollebregt, user guide, "slip velocity dependent
friction", one term of each), with mu_static = mu(0) and mu_kinetic = mu(inf):

* ``constant``: mu(s_a) = mu (Coulomb; today's law, the default);
* ``linear``: mu_k + (mu_s - mu_k) max(0, 1 - s_a / (2 s_h));
* ``rational``: mu_k + (mu_s - mu_k) / (1 + s_a / s_h);
* ``exponential``: mu_k + (mu_s - mu_k) exp(-ln 2 s_a / s_h);
* ``polach``: mu_s ((1 - A) exp(-B s_a) + A) (Polach 2005; the exponential law
  with mu_k = A mu_s and s_h = ln 2 / B).

s_h (``slip_velocity_half``) [length/time] is the slip speed at which the
excess mu - mu_k has halved (linear: at s_a = s_h too); B [time/length].
Every law is a frozen dataclass with vectorised ``mu(s_a)`` [-] and
``dmu_ds(s_a)`` [time/length], for s_a >= 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

LN2 = math.log(2.0)


@dataclass(frozen=True)
class Constant:
    """Coulomb friction: mu(s_a) = ``coefficient`` [-] at every slip speed."""

    coefficient: float
    name = "constant"
    velocity_dependent = False

    @property
    def mu_static(self) -> float:
        """mu at rest [-] (the scale of Q/(mu P))."""
        return self.coefficient

    @property
    def mu_kinetic(self) -> float:
        """mu in sliding [-]: the same."""
        return self.coefficient

    def mu(self, s_a) -> np.ndarray:
        """mu(s_a) [-] for slip speeds s_a >= 0 [length/time]."""
        return np.full(np.shape(s_a), self.coefficient, dtype=float)

    def dmu_ds(self, s_a) -> np.ndarray:
        """d mu / d s_a [time/length]: 0."""
        return np.zeros(np.shape(s_a), dtype=float)

    def describe(self, time_unit: str = "s", length_unit: str = "mm") -> str:
        """One line for the effects table."""
        return f"constant mu = {self.coefficient:g}"


@dataclass(frozen=True)
class _Falling:
    """mu_k + (mu_s - mu_k) f(s_a / s_h) with f(0) = 1, f(inf) = 0 (see the subclasses)."""

    mu_static: float
    mu_kinetic: float
    slip_velocity_half: float
    velocity_dependent = True
    name = ""

    def _shape(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # f(u), f'(u)
        raise NotImplementedError

    def mu(self, s_a) -> np.ndarray:
        """mu(s_a) [-] for slip speeds s_a >= 0 [length/time]."""
        f, _ = self._shape(np.asarray(s_a, dtype=float) / self.slip_velocity_half)
        return self.mu_kinetic + (self.mu_static - self.mu_kinetic) * f

    def dmu_ds(self, s_a) -> np.ndarray:
        """d mu / d s_a [time/length] (<= 0 when mu_kinetic <= mu_static)."""
        _, df = self._shape(np.asarray(s_a, dtype=float) / self.slip_velocity_half)
        return (self.mu_static - self.mu_kinetic) * df / self.slip_velocity_half

    def describe(self, time_unit: str = "s", length_unit: str = "mm") -> str:
        """One line for the effects table."""
        return (
            f"velocity-dependent ({self.name}, mu_s={self.mu_static:g}, mu_k={self.mu_kinetic:g}, "
            f"s_h={self.slip_velocity_half:g} {length_unit}/{time_unit})"
        )


@dataclass(frozen=True)
class Linear(_Falling):
    """mu_k + (mu_s - mu_k) max(0, 1 - s_a / (2 s_h)): linear down to mu_k at s_a = 2 s_h."""

    name = "linear"

    def _shape(self, u):
        inside = u < 2.0
        return np.where(inside, 1.0 - 0.5 * u, 0.0), np.where(inside, -0.5, 0.0)


@dataclass(frozen=True)
class Rational(_Falling):
    """mu_k + (mu_s - mu_k) / (1 + s_a / s_h)."""

    name = "rational"

    def _shape(self, u):
        d = 1.0 / (1.0 + u)
        return d, -d * d


@dataclass(frozen=True)
class Exponential(_Falling):
    """mu_k + (mu_s - mu_k) exp(-ln 2 s_a / s_h)."""

    name = "exponential"

    def _shape(self, u):
        e = np.exp(-LN2 * u)
        return e, -LN2 * e


@dataclass(frozen=True)
class Polach:
    """Polach's law mu_s ((1 - A) exp(-B s_a) + A): A = mu(inf)/mu_s [-], B [time/length]."""

    mu_static: float
    polach_a: float
    polach_b: float
    name = "polach"
    velocity_dependent = True

    @property
    def mu_kinetic(self) -> float:
        """mu(inf) = A mu_s [-]."""
        return self.polach_a * self.mu_static

    def mu(self, s_a) -> np.ndarray:
        """mu(s_a) [-] for slip speeds s_a >= 0 [length/time]."""
        e = np.exp(-self.polach_b * np.asarray(s_a, dtype=float))
        return self.mu_static * ((1.0 - self.polach_a) * e + self.polach_a)

    def dmu_ds(self, s_a) -> np.ndarray:
        """d mu / d s_a [time/length]."""
        e = np.exp(-self.polach_b * np.asarray(s_a, dtype=float))
        return -self.mu_static * (1.0 - self.polach_a) * self.polach_b * e

    def describe(self, time_unit: str = "s", length_unit: str = "mm") -> str:
        """One line for the effects table."""
        return (
            f"velocity-dependent (polach, mu_s={self.mu_static:g}, mu_k={self.mu_kinetic:g}, "
            f"A={self.polach_a:g}, B={self.polach_b:g} {time_unit}/{length_unit})"
        )


@dataclass(frozen=True)
class Blended:
    """mu_s + ``strength`` (mu(s_a) - mu_s): the law ``law`` with its fall scaled by ``strength``
    in [0, 1] (0: Coulomb with mu_static; 1: the law). The homotopy of the solver's law path."""

    law: FrictionLaw
    strength: float
    velocity_dependent = True

    @property
    def name(self) -> str:
        return self.law.name

    @property
    def mu_static(self) -> float:
        return self.law.mu_static

    @property
    def mu_kinetic(self) -> float:
        return self.law.mu_static + self.strength * (self.law.mu_kinetic - self.law.mu_static)

    def mu(self, s_a) -> np.ndarray:
        """mu(s_a) [-]."""
        return self.law.mu_static + self.strength * (self.law.mu(s_a) - self.law.mu_static)

    def dmu_ds(self, s_a) -> np.ndarray:
        """d mu / d s_a [time/length]."""
        return self.strength * self.law.dmu_ds(s_a)

    def describe(self, time_unit: str = "s", length_unit: str = "mm") -> str:
        """One line."""
        return f"{self.law.describe(time_unit, length_unit)} at strength {self.strength:g}"


FrictionLaw = Constant | Linear | Rational | Exponential | Polach | Blended

#: Law names of ``friction.law`` and their classes.
LAWS = {"constant": Constant, "linear": Linear, "rational": Rational, "exponential": Exponential, "polach": Polach}


@dataclass(frozen=True)
class SlipFriction:
    """A velocity-dependent law at a rolling speed |V| = ``speed`` [length/time], as a function of
    the normalised slip s_t [-] the solver works with (s_a = |V| |s_t|)."""

    law: FrictionLaw
    speed: float

    def at(self, s_t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(mu [-], d mu / d s_t [-]) at normalised slips ``s_t``: d mu/d s_t = |V| mu'(s_a) sgn(s_t)."""
        s_a = self.speed * np.abs(s_t)
        return self.law.mu(s_a), self.speed * self.law.dmu_ds(s_a) * np.sign(s_t)


def from_case(friction, rolling) -> FrictionLaw:
    """The law of a validated case's [friction] table (``rolling`` unused: the speed goes to
    :func:`slip_friction`)."""
    law = getattr(friction, "law", "constant")
    if law == "constant":
        return Constant(float(friction.mu))
    if law == "polach":
        return Polach(float(friction.mu_static), float(friction.polach_a), float(friction.polach_b))
    return LAWS[law](float(friction.mu_static), float(friction.mu_kinetic), float(friction.slip_velocity_half))


def slip_friction(case) -> SlipFriction | None:
    """The velocity-dependent friction of a case for the solver, or None for constant friction
    (which keeps the solver's Coulomb code path exactly)."""
    law = from_case(case.friction, case.rolling)
    if not law.velocity_dependent:
        return None
    return SlipFriction(law, float(case.rolling.speed))
