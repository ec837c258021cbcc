"""Which influence model a case needs (``discretization.influence = "auto"``).

The closed-form half-plane is exact for two half-spaces (elastic or rigid
bodies whose contact is small against their radii) loaded by force: it is
then chosen, as it is 10-100 times cheaper than the BEM for the same
discretisation error. The BEM is needed when the closed form does not model
the scene: a layered body (no closed form), or an imposed overlap (the
half-plane's approach is undefined: the log kernel leaves it free; the BEM
half-space measures it from the points at depth D below the contact). A
viscoelastic half-space has only the half-plane kernel
(:mod:`.viscoelastic`); a viscoelastic layer is the BEM layer with history
terms (:mod:`.viscoelastic_layer`).
"bem" and "half-plane" force a model.
"""

from __future__ import annotations

MODELS = ("auto", "bem", "half-plane")


def influence_model(case) -> tuple[str, str]:
    """The model a case resolves to, ``"bem"`` or ``"half-plane"``, and why (one phrase)."""
    requested = case.discretization.influence
    if requested != "auto":
        return requested, f'discretization.influence = "{requested}"'
    finite = [label for label in ("A", "B") if getattr(case.bodies, label).shape == "cylinder"]
    if finite:
        which = f"body {finite[0]} is a finite cylinder" if len(finite) == 1 else "bodies A and B are finite cylinders"
        return "bem", f"auto: {which}, which only the BEM models"
    layered = [label for label in ("A", "B") if getattr(case.bodies, label).kind == "layered"]
    if layered:
        return "bem", f"auto: body {' and '.join(layered)} is layered, which only the BEM models"
    visco = [label for label in ("A", "B") if getattr(case.bodies, label).kind == "viscoelastic"]
    if visco:
        return (
            "half-plane",
            f"auto: body {' and '.join(visco)} is viscoelastic, which the closed-form half-plane models",
        )
    if case.normal.overlap is not None:
        return "bem", "auto: overlap control needs a definite approach, which the closed-form half-plane leaves free"
    return "half-plane", "auto: two half-spaces under load control, where the closed form is exact"
