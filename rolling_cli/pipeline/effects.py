"""Decide which physical effects a case needs, before any work is done.

Every skip is exact, not an approximation:

* **influence model** (:func:`influence_model`): ``"auto"`` takes the
  closed-form half-plane where it is exact (two half-spaces under load
  control) and the BEM otherwise (a layer, overlap control); see
  :mod:`rolling_cli.influence.choice`.
* **coupling** (normal-tangential): skipped when the pair's cross compliance is
  exactly zero: for two half-spaces (closed form or BEM) when Kalker's K/G is
  exactly 0 (similar materials, or a rigid body against an incompressible
  one); with a layer only for identical bodies, whose cross blocks cancel
  exactly (a layer couples strongly whatever its nu).
  Then the normal problem is solved first and the tangential one with p_n held,
  and the coupling blocks are never assembled.
* **tangential problem**: skipped when mu = 0 (frictionless), or when the
  coupling is absent and neither a tangential force nor a creepage is
  prescribed (then p_t = 0 and xi = 0 solve it exactly).
* **influence**: a rigid body gets no mesh and no influence computation;
  identical bodies share one.
* **viscoelastic**: simulated when a body is ``kind = "viscoelastic"`` (the
  steady-rolling half-plane kernels of :mod:`rolling_cli.influence.viscoelastic`,
  the line gives V tau / a) or a layer with ``viscoelastic = true`` (the BEM
  layer with the history terms of :mod:`rolling_cli.influence.viscoelastic_layer`);
  an elastic case builds nothing for it. The
  coupling of a pair with a viscoelastic body is skipped only when both bodies'
  cross compliances agree at every time of the history.

``[effects] coupling = "on" | "off"`` overrides the choice; "off" on a pair that
does couple is allowed but warned about, because it drops a real effect.
"""

from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass, field

from ..case.given import given
from ..case.schema import Body, Case
from ..influence.choice import influence_model
from ..model import materials, viscoelastic

__all__ = ["Effects", "decide", "identical", "cross_compliance", "influence_model"]


@dataclass(frozen=True)
class Effects:
    """What is simulated. ``notes`` maps each effect to "simulated: why" or "skipped: why";
    ``influence`` is the resolved model, "bem" or "half-plane"."""

    strategy: str
    coupling: bool
    tangential: bool
    identical_bodies: bool
    notes: dict[str, str] = field(default_factory=dict)
    warnings: tuple[str, ...] = ()
    influence: str = "half-plane"

    def with_influence_origin(self, origin: dict[str, str]) -> Effects:
        """A copy whose influence notes say where each BEM body came from (computed, cache, reused)."""
        notes = dict(self.notes)
        for label, where in origin.items():
            key = f"influence {label}"
            if key in notes and where in ("computed", "cache", "reused in-process"):
                notes[key] = f"{notes[key]} ({'from disk cache' if where == 'cache' else where})"
        return dataclasses.replace(self, notes=notes)

    def with_coupling_strength(self, strength: float) -> Effects:
        """A copy whose coupling note carries the measured strength max|B_tn| / max|B_tt|."""
        notes = dict(self.notes)
        if notes.get("coupling", "").startswith("simulated"):
            notes["coupling"] += f"; measured max|B_tn|/max|B_tt| = {strength:.3g}"
        return dataclasses.replace(self, notes=notes)

    def line(self) -> str:
        """All effects in one line (the result file's ``effects_line``; the screen prints
        :meth:`lines`)."""
        return "; ".join(self.lines())

    def lines(self) -> list[str]:
        """One short line per effect, ``name: simulated|skipped: why``."""
        return [f"{name}: {text}" for name, text in self.notes.items()]

    def to_json(self) -> str:
        """JSON text for the result file's ``effects`` attribute."""
        return json.dumps(
            {
                "strategy": self.strategy,
                "influence": self.influence,
                "coupling": self.coupling,
                "tangential": self.tangential,
                "identical_bodies": self.identical_bodies,
                "notes": self.notes,
                "warnings": list(self.warnings),
            }
        )


def identical(a: Body, b: Body) -> bool:
    """True when both bodies have the same model and material (so the same influence)."""
    return (
        a.kind == b.kind
        and not a.rigid
        and a.young == b.young
        and a.poisson == b.poisson
        and a.layer_thickness == b.layer_thickness
        and a.relaxed_young == b.relaxed_young
        and a.creep_time == b.creep_time
        and a.prony == b.prony
        and a.viscoelastic == b.viscoelastic
        and a.shape == b.shape
        and (not a.finite or (a.radius == b.radius and a.inner_radius == b.inner_radius))
        and a.core_young == b.core_young
        and a.core_poisson == b.core_poisson
    )


def _shape_phrase(label: str, body: Body) -> str:
    """``A: R = 5, bore 2`` (elastic), ``A: R = 5, core 4`` (a cover on a rigid core) or
    ``A: R = 25, cover 5 on an elastic core, bore 1`` (:attr:`~rolling_cli.case.schema.Body.elastic_core`)."""
    if body.elastic_core:
        return (
            f"{label}: R = {body.radius:g}, cover {body.layer_thickness:g} on an elastic core, bore {body.core_bore:g}"
        )
    what = "core" if body.kind == "layered" else "bore"
    return f"{label}: R = {body.radius:g}, {what} {body.core_radius:g}"


def cross_compliance(case: Case) -> float:
    """Kalker's K/G of the pair [1/stress] in the half-plane sense (0 means no coupling)."""
    a, b = case.bodies.A, case.bodies.B
    return materials.kalker_k_over_g(a.modulus, a.ratio, b.modulus, b.ratio)


def _relaxed_half_width(case: Case) -> float:
    """Hertz a [length] of the pair with the relaxed moduli (the mesh scale of a viscoelastic case);
    under overlap control (a viscoelastic layer) the layer's estimate of the planning's first guess
    (:func:`rolling_cli.references.thin_layer.half_width_for_overlap`)."""
    from ..references import hertz, thin_layer

    a, b = case.bodies.A, case.bodies.B
    e_star = materials.effective_modulus(a.modulus, a.ratio, b.modulus, b.ratio)
    r_star = materials.effective_radius(a.radius, b.radius)
    if case.normal.load is None:
        incompressible = any(body.kind == "layered" and body.ratio >= 0.45 for body in (a, b))
        overlap = given(case.normal.overlap, "normal.overlap")
        return thin_layer.half_width_for_overlap(overlap, r_star, incompressible)
    return hertz.half_width(given(case.normal.load, "normal.load"), r_star, e_star)


def decide(case: Case) -> Effects:
    """The effects the case calls for (see the module docstring).

    Over 80 lines for a reason: one decision per effect, in the order the module docstring
    lists them, each next to the note it writes; split up, that order would be hidden.
    """
    a, b = case.bodies.A, case.bodies.B
    mu = case.friction.mu
    kind, value = case.tangential.control()
    same = identical(a, b)
    notes: dict[str, str] = {}
    warnings: list[str] = []
    model, why_model = influence_model(case)
    bem = model == "bem"
    layered = a.kind == "layered" or b.kind == "layered"
    k_over_g = cross_compliance(case)
    visco = viscoelastic.bodies(case)
    beta = materials.dundurs_beta(a.modulus, a.ratio, b.modulus, b.ratio)

    if same and bem:
        physical = False
        why_zero = "identical bodies: the BEM cross blocks cancel exactly"
        why_on = ""
    elif layered or a.finite or b.finite:
        physical = True
        why_zero = ""
        why_on = (
            "a layer couples normal and tangential tractions whatever its nu (BEM cross blocks)"
            if layered
            else "a finite cylinder's curved surface couples normal and tangential tractions (BEM cross blocks)"
        )
    elif visco:
        physical = viscoelastic.cross_differs(case)
        why_zero = "the bodies' cross compliances are equal at all times of the history, exactly decoupled"
        why_on = (
            "the cross compliances differ over the load history (viscoelastic body; "
            f"beta (Dundurs) = {beta:.4g} with the relaxed moduli)"
        )
    else:
        physical = k_over_g != 0.0
        why_zero = "beta (Dundurs) = 0, exactly decoupled" + (" (the BEM models half-spaces)" if bem else "")
        why_on = f"dissimilar materials, beta (Dundurs) = {beta:.4g}"

    choice = case.effects.coupling
    frictionless = mu == 0.0
    if frictionless:
        coupling = False
        notes["coupling"] = "skipped: frictionless (mu = 0), p_t = 0"
    elif choice == "on":
        coupling = True
        notes["coupling"] = 'simulated: forced by effects.coupling = "on"' + ("" if physical else f" ({why_zero})")
    elif choice == "off":
        coupling = False
        notes["coupling"] = 'skipped: effects.coupling = "off"'
        if physical:
            warnings.append(f'effects.coupling = "off" drops a real effect: {why_on}')
    else:
        coupling = physical
        notes["coupling"] = f"simulated: {why_on}" if physical else f"skipped: {why_zero}"

    free = (kind == "load" and value == 0.0) or (kind in ("q_over_mu_p", "q_over_p", "creep") and value == 0.0)
    if frictionless:
        tangential = False
        notes["tangential"] = "skipped: frictionless (mu = 0), no tangential unknowns"
    elif free and not coupling:
        tangential = False
        notes["tangential"] = "skipped: no tangential load and no coupling, so p_t = 0 and xi = 0 exactly"
    else:
        tangential = True
        notes["tangential"] = f"simulated: {kind} = {value:g}"

    notes["normal"] = "simulated: " + ("load" if case.normal.load is not None else "overlap") + " control"
    if not bem:
        rigid = [label for label, body in (("A", a), ("B", b)) if body.rigid]
        notes["influence"] = (
            "closed-form half-plane pair, one computation"
            + (f" (body {rigid[0]} rigid: no compliance)" if rigid else "")
            + f" ({why_model})"
        )
    else:
        notes["influence"] = f"BEM ({why_model})"
        for label, body in (("A", a), ("B", b)):
            if body.rigid:
                notes[f"influence {label}"] = "skipped: rigid body, no mesh"
            elif label == "B" and same:
                notes[f"influence {label}"] = "reused: identical to body A"
            else:
                kind = "BEM layer on a rigid core" if body.kind == "layered" else "BEM half-space"
                if body.finite:
                    kind = "BEM finite cylinder, " + (
                        ("cover on an elastic core" if body.elastic_core else "cover on a rigid core")
                        if body.kind == "layered"
                        else "bore on a rigid shaft"
                    )
                notes[f"influence {label}"] = f"simulated: {kind}"
        finite = [_shape_phrase(label, body) for label, body in (("A", a), ("B", b)) if body.finite]
        if finite:
            notes["body shape"] = "finite cylinder (" + "; ".join(finite) + ")"

    from ..model.friction import from_case

    law = from_case(case.friction, case.rolling)
    notes["friction"] = law.describe(case.units.time, case.units.length)
    if law.velocity_dependent:
        notes["friction"] += f" at |V| = {case.rolling.speed:g} {case.units.length}/{case.units.time}"
    if visco:
        notes["viscoelastic"] = f"simulated ({viscoelastic.speed_ratio_text(case, _relaxed_half_width(case))})"
    else:
        notes["viscoelastic"] = "skipped: no viscoelastic body"

    if case.stresses is None:
        notes["stresses"] = "skipped: not requested (no [stresses] table)"
    else:
        from ..stresses.report import planned_note

        notes["stresses"] = planned_note(case)
    strategy = "coupled" if coupling else ("decoupled" if tangential else "normal")
    return Effects(strategy, coupling, tangential, same, notes, tuple(warnings), model)
