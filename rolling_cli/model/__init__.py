"""The physical model beyond the linear elastic half-space: constitutive laws and body models.

Each module is a set of pure, vectorised functions or frozen dataclasses with
their units in the docstrings; the solver and the influence models import
them, never the other way round. Friction as a law of the slip speed
(:mod:`~rolling_cli.model.friction`), viscoelastic materials in steady rolling
(:mod:`~rolling_cli.model.viscoelastic`: the standard linear solid and Prony
series; the rolling resistance they cause, :mod:`~rolling_cli.model.resistance`),
the body's shape (:mod:`~rolling_cli.model.shapes`: the half-space of the seed
paper, or the finite cross-section of a cylinder, hollow on a rigid shaft or
covered on a rigid core; its exact gap and hoop strain, :mod:`~rolling_cli.influence.finite`).
"""
