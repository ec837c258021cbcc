"""Linear viscoelastic bodies: the standard linear solid and Prony series, as creep compliances.

A viscoelastic body (``kind = "viscoelastic"``) has a constant Poisson ratio and
a creep compliance (strain per unit stress held from t = 0) of the form

    J(t) = 1/E_g + sum_i c_i (1 - exp(-t / lambda_i))        [1/stress]

with the glassy (instantaneous) modulus E_g, the compliance increments c_i > 0
and the retardation (creep) times lambda_i > 0; J(inf) = 1/E_r, E_r the relaxed
(long-time) modulus. Case keys under ``[bodies.X]``:

* standard linear solid: ``young`` = E_g, ``relaxed_young`` = E_r <= E_g and
  ``creep_time`` = tau_c, the retardation time of J(t) (CONTACT's ``TC``; the
  relaxation time of E(t) is tau_r = tau_c E_r / E_g). One term,
  c = 1/E_r - 1/E_g, lambda = tau_c.
* Prony series (DMA master curves): ``young`` = E_g and
  ``prony = [[E_1, tau_1], ...]``, the relaxation modulus
  E(t) = E_r + sum_i E_i exp(-t / tau_i) with E_r = E_g - sum E_i > 0, E_i > 0,
  tau_i > 0 the relaxation times. It is converted to the creep form above
  (:func:`prony_relaxation`): the lambda_i are the roots of the Laplace-domain
  modulus s E(s), the c_i its residues.

In steady rolling at speed |V| a surface point meets the load upstream a time
t = distance / |V| earlier, so each term acts through the length
ell_i = |V| lambda_i (:meth:`Viscoelastic.lengths`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import CaseError


@dataclass(frozen=True)
class Viscoelastic:
    """Creep compliance of a body: ``young`` = E_g, the glassy (instantaneous) modulus [stress],
    ``compliances`` c_i [1/stress] and ``times`` lambda_i [time] of the retardation terms,
    ``poisson`` nu [-] (constant in time), ``label`` "elastic", "SLS" or "Prony (N terms)"."""

    young: float
    compliances: tuple[float, ...]
    times: tuple[float, ...]
    poisson: float
    label: str = "SLS"

    @property
    def glassy(self) -> float:
        """J(0) = 1/E_g [1/stress]."""
        return 1.0 / self.young

    @property
    def elastic(self) -> bool:
        """True without retardation terms: J(t) = 1/E at all times."""
        return not self.compliances

    @property
    def relaxed(self) -> float:
        """J(inf) = 1/E_r [1/stress]."""
        return self.glassy + float(sum(self.compliances))

    @property
    def glassy_young(self) -> float:
        """E_g [stress]."""
        return self.young

    @property
    def relaxed_young(self) -> float:
        """E_r [stress] (E itself for an elastic material)."""
        return self.young if self.elastic else 1.0 / self.relaxed

    def creep(self, t) -> np.ndarray:
        """J(t) [1/stress] at times ``t`` [time] (t >= 0)."""
        t = np.asarray(t, dtype=float)
        out = np.full(t.shape, self.glassy)
        for c, lam in zip(self.compliances, self.times, strict=True):
            out = out - c * np.expm1(-t / lam)
        return out

    def lengths(self, speed: float) -> tuple[float, ...]:
        """ell_i = |V| lambda_i [length] for the rolling speed |V| [length/time]."""
        return tuple(float(speed) * lam for lam in self.times)

    def longest_time(self) -> float:
        """The longest retardation time [time] (0 without terms)."""
        return max(self.times, default=0.0)


def standard_linear_solid(glassy_young: float, relaxed_young: float, creep_time: float, poisson: float) -> Viscoelastic:
    """The SLS of E_g, E_r [stress] and the creep (retardation) time tau_c [time]."""
    c = 1.0 / relaxed_young - 1.0 / glassy_young
    return Viscoelastic(float(glassy_young), (c,), (float(creep_time),), float(poisson), "SLS")


def prony_relaxation(glassy_young: float, terms, poisson: float) -> Viscoelastic:
    """Creep form of the relaxation modulus E(t) = E_r + sum E_i exp(-t/tau_i), E_r = E_g - sum E_i.

    ``terms``: pairs (E_i [stress] > 0, tau_i [time] > 0). Terms of equal tau are merged.
    The Laplace-domain modulus is D(s) = s E(s) = E_r + sum E_i s tau_i / (1 + s tau_i);
    the creep compliance's transform is 1 / (s D(s)), whose poles s_k = -1/lambda_k are
    the N roots of D, one between each pair of neighbouring poles -1/tau_i of D (D is
    monotone there), and whose residues give c_k = lambda_k / D'(s_k).
    """
    from scipy.optimize import brentq

    merged: dict[float, float] = {}
    for e_i, tau in terms:
        merged[float(tau)] = merged.get(float(tau), 0.0) + float(e_i)
    taus = np.array(sorted(merged, reverse=True))  # poles rho = 1/tau ascending
    moduli = np.array([merged[t] for t in taus])
    relaxed = glassy_young - float(moduli.sum())
    if not relaxed > 0.0:
        raise ValueError("the Prony terms sum to the glassy modulus or more")

    def d_of(rho: float) -> float:  # D(-rho)
        return relaxed - float(np.sum(moduli * rho * taus / (1.0 - rho * taus)))

    def slope(rho: float) -> float:  # dD/ds at s = -rho
        return float(np.sum(moduli * taus / (1.0 - rho * taus) ** 2))

    poles = 1.0 / taus
    lows = np.concatenate([[0.0], poles[:-1]])
    compliances, times = [], []
    for lo, hi in zip(lows, poles, strict=True):
        eps = 1e-12
        left = lo * (1.0 + eps) if lo > 0.0 else 0.0
        rho = brentq(d_of, left, hi * (1.0 - eps), xtol=1e-300, rtol=1e-15, maxiter=400)
        compliances.append(1.0 / (rho * slope(rho)))
        times.append(1.0 / rho)
    label = f"Prony ({len(taus)} term{'s' if len(taus) > 1 else ''})"
    return Viscoelastic(float(glassy_young), tuple(compliances), tuple(times), float(poisson), label)


#: The material of a deformable body: its creep compliance J(t) at a constant Poisson ratio. A linear
#: elastic body is the material without retardation terms (J = 1/E at all times, :func:`elastic`).
Material = Viscoelastic


def elastic(young: float, poisson: float) -> Material:
    """The linear elastic material of Young's modulus E [stress] and Poisson ratio nu [-]: J(t) = 1/E."""
    return Viscoelastic(float(young), (), (), float(poisson), "elastic")


def material(body) -> Material | None:
    """The material of a case body: elastic (also a layered body's layer) or viscoelastic; None if rigid."""
    if body.kind == "rigid":
        return None
    return from_body(body) or elastic(float(body.young), float(body.poisson))


def is_viscoelastic(body) -> bool:
    """True for a viscoelastic half-space (``kind = "viscoelastic"``) or a viscoelastic layer
    (``kind = "layered"`` with ``viscoelastic = true``, the rubber cover on a rigid core)."""
    return body.kind == "viscoelastic" or (body.kind == "layered" and bool(getattr(body, "viscoelastic", False)))


def viscoelastic_layer(body) -> bool:
    """True for a viscoelastic layer on a rigid core (:mod:`rolling_cli.influence.viscoelastic_layer`)."""
    return body.kind == "layered" and is_viscoelastic(body)


def from_body(body) -> Viscoelastic | None:
    """The creep compliance of a case body (:class:`~rolling_cli.case.schema.Body`); None unless viscoelastic."""
    if not is_viscoelastic(body):
        return None
    if body.prony is not None:
        return prony_relaxation(float(body.young), body.prony, float(body.poisson))
    return standard_linear_solid(
        float(body.young), float(body.relaxed_young), float(body.creep_time), float(body.poisson)
    )


def bodies(case) -> dict[str, Viscoelastic]:
    """The case's viscoelastic bodies by label ("A", "B")."""
    out = {}
    for label in ("A", "B"):
        model = from_body(getattr(case.bodies, label))
        if model is not None:
            out[label] = model
    return out


def relaxed_modulus(body) -> float:
    """E_r [stress] of a viscoelastic case body (the mesh scale: its contact is the widest)."""
    if body.prony is not None:
        return float(body.young) - float(sum(e for e, _ in body.prony))
    return float(body.relaxed_young)


# --- case checks ----------------------------------------------------------------------------------


def prony_terms(value: Any, key: str, file: str | None) -> tuple[tuple[float, float], ...]:
    """Convert ``prony``: a non-empty list of [E_i, tau_i] pairs of positive finite numbers."""
    allowed = "a list of [E_i, tau_i] pairs, E_i > 0 [stress] and tau_i > 0 [time], at most 50"
    ok = isinstance(value, (list, tuple)) and 0 < len(value) <= 50
    pairs = []
    if ok:
        for item in value:
            if not (isinstance(item, (list, tuple)) and len(item) == 2):
                ok = False
                break
            if any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in item):
                ok = False
                break
            e_i, tau = float(item[0]), float(item[1])
            if not (math.isfinite(e_i) and math.isfinite(tau)):
                ok = False
                break
            if not (e_i > 0.0 and tau > 0.0):
                shown = repr(value) if len(repr(value)) <= 60 else repr(value)[:57] + "..."
                raise CaseError(
                    f"{key} = {shown}: a non-positive modulus or time ([{item[0]!r}, {item[1]!r}]); allowed: {allowed}",
                    file=file,
                    key=key,
                )
            pairs.append((e_i, tau))
    if not ok:
        shown = repr(value) if len(repr(value)) <= 60 else repr(value)[:57] + "..."
        raise CaseError(f"{key} = {shown}: not a Prony series; allowed: {allowed}", file=file, key=key)
    return tuple(pairs)


def check_body(body, key: str, file: str | None) -> None:
    """Cross-key rules of a viscoelastic body ``key`` = "bodies.X" (CaseError, one line)."""
    if getattr(body, "viscoelastic", False) and body.kind in ("elastic", "rigid"):
        raise CaseError(
            f'{key}.viscoelastic = true: not used by kind = "{body.kind}"; allowed: kind = "viscoelastic" '
            '(a viscoelastic half-space) or kind = "layered" (a viscoelastic cover on a rigid core)',
            file=file,
            key=f"{key}.viscoelastic",
        )
    if not is_viscoelastic(body):
        for name in ("relaxed_young", "creep_time", "prony"):
            if getattr(body, name) is not None:
                hint = ", or viscoelastic = true" if body.kind == "layered" else ', or kind = "viscoelastic"'
                raise CaseError(
                    f'{key}.{name} = {getattr(body, name)!r}: not used by kind = "{body.kind}"; '
                    f"allowed: remove it{hint}",
                    file=file,
                    key=f"{key}.{name}",
                )
        return
    if body.prony is not None:
        for name in ("relaxed_young", "creep_time"):
            if getattr(body, name) is not None:
                raise CaseError(
                    f"{key}.{name} = {getattr(body, name)!r}: given with {key}.prony; allowed: either prony "
                    "(with young = E_g) or relaxed_young and creep_time",
                    file=file,
                    key=f"{key}.{name}",
                )
        total = sum(e for e, _ in body.prony)
        if not total < float(body.young):
            raise CaseError(
                f"{key}.prony = {list(map(list, body.prony))!r}: the terms sum to {total:g}, not below the glassy "
                f"modulus young = {body.young:g}; allowed: sum E_i < young (E_r = young - sum E_i > 0)",
                file=file,
                key=f"{key}.prony",
            )
        return
    what = 'kind = "viscoelastic"' if body.kind == "viscoelastic" else "viscoelastic = true"
    for name in ("relaxed_young", "creep_time"):
        if getattr(body, name) is None:
            raise CaseError(
                f"{key}.{name}: missing key ({what}); allowed: a number > 0, or {key}.prony instead",
                file=file,
                key=f"{key}.{name}",
            )
    if body.relaxed_young > body.young:
        raise CaseError(
            f"{key}.relaxed_young = {body.relaxed_young:g}: above the glassy modulus young = {body.young:g}; "
            f"allowed: 0 < relaxed_young <= young",
            file=file,
            key=f"{key}.relaxed_young",
        )


def check_case(case, file: str | None) -> None:
    """Case-wide rules once any body is viscoelastic: ``rolling.speed`` given, a uniform grid;
    a viscoelastic half-space on the closed-form half-plane under load control, not paired with a
    layer (a viscoelastic finite cylinder is on the BEM, under either control); a viscoelastic
    layer (the BEM layer with its history terms) not paired with a viscoelastic half-space."""
    labels = [label for label in ("A", "B") if is_viscoelastic(getattr(case.bodies, label))]
    if not labels:
        return
    body = getattr(case.bodies, labels[0])
    phrase = 'kind = "viscoelastic"' if body.kind == "viscoelastic" else "viscoelastic = true"
    first = f"bodies.{labels[0]}.{phrase}"
    if case.rolling.speed is None:
        raise CaseError(
            f"rolling.speed: missing key ({first}); allowed: the rolling speed |V| > 0 [length/time]",
            file=file,
            key="rolling.speed",
        )
    disc = case.discretization
    if disc.tolerance is not None:
        raise CaseError(
            f"discretization.tolerance = {disc.tolerance!r}: adaptive (graded) meshes have no viscoelastic kernel "
            f"yet ({first}); allowed: remove it (a uniform grid)",
            file=file,
            key="discretization.tolerance",
        )
    halves = [
        label
        for label in labels
        if getattr(case.bodies, label).kind == "viscoelastic" and getattr(case.bodies, label).shape != "cylinder"
    ]  # a viscoelastic finite cylinder is the BEM annulus with its periodic history (any control)
    if not halves:
        return
    first = f'bodies.{halves[0]}.kind = "viscoelastic"'
    others = [label for label in ("A", "B") if getattr(case.bodies, label).kind == "layered"]
    if others:
        raise CaseError(
            f'bodies.{others[0]}.kind = "layered": a layer with a viscoelastic half-space ({first}) is not '
            'modelled yet; allowed: "elastic" | "rigid" | "viscoelastic"',
            file=file,
            key=f"bodies.{others[0]}.kind",
        )
    if disc.influence == "bem":
        raise CaseError(
            f'discretization.influence = "bem": a viscoelastic body ({first}) has only the closed-form '
            'half-plane kernel; allowed: "auto" | "half-plane"',
            file=file,
            key="discretization.influence",
        )
    if case.normal.load is None:
        raise CaseError(
            f"normal.overlap = {case.normal.overlap!r}: a viscoelastic case ({first}) is on the half-plane, "
            "which is loaded by force; allowed: normal.load",
            file=file,
            key="normal.overlap",
        )


def speed_ratio_text(case, half_width: float) -> str:
    """The effects-line text, e.g. "B: SLS, V tau_c / a = 1.6" (a [length] the contact scale)."""
    parts = []
    speed = float(case.rolling.speed)
    for label, model in bodies(case).items():
        if model.label == "SLS":
            parts.append(f"{label}: SLS, V tau_c / a = {speed * model.times[0] / half_width:.3g}")
        else:
            parts.append(f"{label}: {model.label}, V lambda_max / a = {speed * model.longest_time() / half_width:.3g}")
    return "; ".join(parts)


def cross_history(body) -> tuple:
    """The normal-tangential cross compliance of a body over time, as comparable data:
    (k J_g, ((k c_i, lambda_i), ...)) with k = (1 - 2 nu)(1 + nu)/2 [1/stress]; zero for a rigid body."""
    if body.rigid:
        return (0.0, ())
    nu = float(body.poisson)
    k = 0.5 * (1.0 - 2.0 * nu) * (1.0 + nu)
    model = from_body(body)
    if model is None:
        return (k / float(body.young), ())
    if k == 0.0:
        return (0.0, ())
    return (
        k * model.glassy,
        tuple(sorted((k * c, lam) for c, lam in zip(model.compliances, model.times, strict=True))),
    )


def cross_differs(case) -> bool:
    """True when the pair's cross compliance (A's minus B's) is not zero at every time of the
    history, so the coupling is physical (a viscoelastic body in the pair)."""
    return cross_history(case.bodies.A) != cross_history(case.bodies.B)
