"""Every scalar a result holds, declared once: its name, type, unit and long name.

The groups below are the scalar fields of :class:`rolling_cli.result.Result`
(it inherits them); the file layout (:mod:`rolling_cli.files.layout`) takes the
``units`` and ``long_name`` attributes of the file's ``(case)`` variables from
the same declarations, so the Python object and the file cannot drift apart.

A quantity is ``None`` until a stage records it (``None`` is "not recorded":
the writer leaves it out, as a file leaves out a variable); a result read from
a file has the quantities that file recorded.

Units are keys into the result's unit names (:attr:`Result.units`):
``"length"``, ``"stress"``, ``"force/length"``, ``"stress/length"``, ``"length/time"``,
``"moment/length"`` (a moment per unit axial length, force/length times length), ``"1"``
(dimensionless: ratios, counts, flags, relative values), ``"s"`` (wall time),
the quotients ``"1/(force/length)"``, ``"length/(force/length)"``,
``"stress/(force/length)"`` (derivatives with respect to a load), ``"1/(length)"``
(a creepage's derivative with respect to a length), ``"force/length/(length/time)"`` and
``"1/(length/time)"`` (derivatives with respect to the rolling speed);
``None`` for text and booleans, which carry no unit.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

#: Unit keys a quantity may have (module docstring).
UNIT_KEYS = (
    "length",
    "stress",
    "force/length",
    "stress/length",
    "length/time",
    "moment/length",
    "1",
    "s",
    "1/(force/length)",
    "length/(force/length)",
    "stress/(force/length)",
    "1/(length)",
    "force/length/(length/time)",
    "1/(length/time)",
    None,
)


class Quantity(NamedTuple):
    """The declaration of one scalar: its long name, unit key and Python type."""

    long_name: str
    unit: str | None
    kind: str  # "float", "int", "bool", "str" or "array" (a per-case array of its own length)


def quantity(long_name: str, unit: str | None, kind: str = "float") -> Any:
    """A result field holding one declared quantity (None until recorded)."""
    if unit not in UNIT_KEYS:
        raise ValueError(f"unit key {unit!r} of {long_name!r}: one of {UNIT_KEYS}")
    return dataclasses.field(default=None, metadata={"quantity": Quantity(long_name, unit, kind)})


def text(long_name: str) -> Any:
    """A text quantity (no unit)."""
    return quantity(long_name, None, "str")


def count(long_name: str) -> Any:
    """An integer quantity (dimensionless)."""
    return quantity(long_name, "1", "int")


@dataclass(kw_only=True)
class Provenance:
    """What wrote the result (root attributes of a file, not (case) variables, but ``title``)."""

    format: str | None = text("file format name")
    format_version: int | None = quantity("file format version", "1", "int")
    software_version: str | None = text("rolling_cli version that solved the case")
    created: str | None = text("when the result was made (ISO 8601, UTC)")
    title: str | None = text("title of the case")


@dataclass(kw_only=True)
class Convergence:
    """How the solve went."""

    converged: bool | None = quantity("the solve converged to the tolerance", None, "bool")
    iterations: int | None = count("Newton iterations of the final mesh level, all stages together")
    iterations_total: int | None = count("Newton iterations of every mesh level of the solve")
    residual: float | None = quantity("final relative residual", "1")
    tolerance_applied: float | None = quantity("relative residual tolerance the final stage applied", "1")
    strategies: str | None = text("solver strategies run, by mesh level")
    start: str | None = text("start of the solve: cold (closed forms) or warm (a neighbouring case)")
    start_traction: str | None = text("traction of a warm start: the neighbours' or the closed form's")
    message: str | None = text("why the case failed (empty when it converged)")
    linear_solver: str | None = text("linear solver of the Newton steps")
    krylov_solves: int | None = count("Krylov solves of the Newton steps (matrix-free)")
    krylov_iterations: int | None = count("Krylov iterations of the Newton steps (matrix-free)")
    krylov_dense_fallbacks: int | None = count("Krylov solves that fell back to a dense factorisation")
    zone_note: str | None = text("how the potential contact zone was enlarged")


@dataclass(kw_only=True)
class Loads:
    """Loads, creepage and approach of the solved case."""

    normal_load: float | None = quantity(
        "normal load P = -sum w p_n per unit axial length (a finite cylinder: the load on its shaft, shaft_load)",
        "force/length",
    )
    tangential_load: float | None = quantity(
        "tangential load Q = sum w p_t on body A per unit axial length", "force/length"
    )
    q_over_mu_p: float | None = quantity("Q/(mu P) (mu: mu_static of a velocity-dependent law)", "1")
    creep: float | None = quantity("creepage xi = (V_A - V_B)/|V|", "1")
    overlap: float | None = quantity("rigid overlap (NaN where undefined)", "length")
    solved_overlap: float | None = quantity("overlap unknown of the solve (the half-plane's free constant)", "length")
    mu: float | None = quantity("coefficient of friction (mu_static of a velocity-dependent law)", "1")
    direction: int | None = count("sign of the rolling velocity V (-1 where the case failed before solving)")
    carter_creep: float | None = quantity("Carter's creepage for the solved Q/(mu P)", "1")
    frictional_power_total: float | None = quantity(
        "frictional power per unit rolling speed and axial length, sum w (-p_t s_t)", "force/length"
    )


@dataclass(kw_only=True)
class Friction:
    """A velocity-dependent friction law (:mod:`rolling_cli.model.friction`); not recorded for
    Coulomb friction, whose ``mu`` says it all. ``mu`` is then the law's mu_static, the scale of
    Q/(mu P)."""

    friction_law: str | None = text("friction law mu(s_a) of the slip speed s_a = |V| |s_t|")
    mu_kinetic: float | None = quantity("kinetic coefficient of friction mu(inf) of the law", "1")
    rolling_speed: float | None = quantity("rolling speed |V|", "length/time")
    unit_time: str | None = text("unit of time")
    creep_slope: float | None = quantity(
        "slope dQ/dxi of the creep-force curve at the solution (node states held)", "force/length"
    )
    branch: str | None = text('branch of the creep-force curve: "rising" (dQ/dxi < 0, stable) or "falling"')
    other_branch_creep: float | None = quantity(
        "creepage of the other steady solution for the same force (solver.branch chose this one)", "1"
    )
    branch_note: str | None = text("the steady solutions of the prescribed force and the one chosen")


@dataclass(kw_only=True)
class Contact:
    """The contact patch, its Hertz scales and the model's validity."""

    hertz_a: float | None = quantity("Hertz half-width at the solved load", "length")
    hertz_p0: float | None = quantity("Hertz peak pressure at the solved load", "stress")
    mesh_half_width: float | None = quantity("length a that scales the mesh", "length")
    beta_dundurs: float | None = quantity("Dundurs' beta", "1")
    beta_seed: float | None = quantity("2 beta_Dundurs (the paper's beta)", "1")
    contact_half_width: float | None = quantity("half-width of the contact (node cells included)", "length")
    contact_centre: float | None = quantity("centre of the contact", "length")
    coupling_strength: float | None = quantity("measured coupling max|B_tn| / max|B_tt|", "1")
    half_space_ratio: float | None = quantity("a/R of the most curved body (the half-space model needs it small)", "1")
    validity_warning: str | None = text("why the model does not describe the bodies (empty when it does)")
    shaft_load: float | None = quantity(
        "finite cylinder: normal resultant of the contact tractions on the shaft (NaN: no finite body)", "force/length"
    )
    shaft_tangential_load: float | None = quantity(
        "finite cylinder: tangential resultant of the contact tractions on body A's shaft (NaN: no finite body)",
        "force/length",
    )
    shaft_torque: float | None = quantity(
        "finite cylinder: moment about the finite body's shaft axis that its shaft transmits, R Q "
        "(NaN: no finite body)",
        "moment/length",
    )
    contact_angle: float | None = quantity(
        "finite cylinder: angular position of the contact centre on its outer circle, rad (NaN: no finite body)", "1"
    )
    contact_arc: float | None = quantity(
        "finite cylinder: angle the contact spans on its outer circle, rad (NaN: no finite body)", "1"
    )
    arc_load: float | None = quantity(
        "finite cylinder: arc sum -sum w p_n of the contact pressure per unit axial length; the normal load P "
        "is the shaft load (NaN: no finite body)",
        "force/length",
    )


@dataclass(kw_only=True)
class Model:
    """The discrete model: influence, grid, penalties, effects and units."""

    influence: str | None = text("influence model")
    bodies: str | None = text("body kinds")
    effects: str | None = text("effects simulated and skipped, and why (JSON)")
    effects_line: str | None = text("effects simulated and skipped, one line")
    contact_elements: int | None = count("elements over the potential contact zone")
    element_order: int | None = count("order of the contact elements (0 constant, 2 quadratic)")
    element_edges: np.ndarray | None = quantity(
        "element edges of the graded contact grid (x, in the solver's frame)", "length", "array"
    )
    node_spacing: float | None = quantity("spacing of the contact nodes", "length")
    penalty_n: float | None = quantity("normal penalty r_n", "stress/length")
    penalty_t: float | None = quantity("tangential penalty r_t", "stress")
    reference_penalty_n: float | None = quantity("reference normal penalty of the residual", "stress/length")
    reference_penalty_t: float | None = quantity("reference tangential penalty of the residual", "stress")
    traction_scale: float | None = quantity("max |p_n|, the scale of the relative residual", "stress")
    unit_length: str | None = text("unit of lengths")
    unit_stress: str | None = text("unit of stresses")
    unit_line_force: str | None = text("unit of forces per unit axial length")


@dataclass(kw_only=True)
class Timings:
    """Wall times [s]."""

    time: float | None = quantity("wall time of the case", "s")
    time_influence: float | None = quantity("wall time of the influence build", "s")
    time_solve: float | None = quantity("wall time of the Newton solve", "s")
    time_total_solve: float | None = quantity("wall time of the solve, every mesh level", "s")
    time_stresses: float | None = quantity("wall time of the subsurface stresses", "s")
    time_sensitivities: float | None = quantity("wall time of the sensitivities (one linear solve each)", "s")
    time_total: float | None = quantity("wall time of the whole command", "s")


@dataclass(kw_only=True)
class Adaptive:
    """The adaptive mesh record (``discretization.tolerance``)."""

    adaptive_tolerance: float | None = quantity("requested traction accuracy, of mu p0", "1")
    adaptive_estimate: float | None = quantity("estimated traction error of the final mesh, of mu p0", "1")
    adaptive_met: bool | None = quantity("the estimate met the requested tolerance", None, "bool")
    adaptive_refinements: int | None = count("mesh refinements made")
    adaptive_method: str | None = text("how the meshes were refined")
    adaptive_note: str | None = text("how the adaptive loop ended")
    adaptive_creep_change: float | None = quantity("relative change of the creepage at the last refinement", "1")
    adaptive_history: str | None = text("elements, estimate and creepage of each mesh (JSON)")


@dataclass(kw_only=True)
class ErrorEstimate:
    """The accuracy estimate of ``rollc solve --error-estimate``."""

    error_estimate: float | None = quantity("estimated largest traction error, of mu p0 (of p0 frictionless)", "1")
    error_estimate_rms: float | None = quantity("estimated RMS traction error over the contact, of mu p0", "1")
    error_estimate_creep: float | None = quantity("estimated relative creepage error", "1")
    error_estimate_load: float | None = quantity("estimated relative normal load error", "1")
    error_estimate_elements: int | None = count("contact elements of the comparison mesh")
    error_estimate_method: str | None = text("how the error was estimated")
    error_estimate_note: str | None = text("why there is no estimate, or what it is")


@dataclass(kw_only=True)
class StressMaxima:
    """The subsurface stress indicators ([stresses]): the largest value over the bodies, where."""

    stress_bodies: str | None = text("bodies whose stress fields were computed")
    stress_length_scale: float | None = quantity("length scale a of the stress grid", "length")
    stress_pressure_scale: float | None = quantity(
        "pressure scale p0 (peak pressure) of the stress indicators", "stress"
    )
    stress_max_von_mises: float | None = quantity("largest von Mises stress", "stress")
    stress_max_von_mises_x_over_a: float | None = quantity("x/a of the largest von Mises stress", "1")
    stress_max_von_mises_z_over_a: float | None = quantity("z/a of the largest von Mises stress", "1")
    stress_max_von_mises_body: str | None = text("body of the largest von Mises stress")
    stress_max_tresca: float | None = quantity("largest Tresca stress sigma_1 - sigma_3", "stress")
    stress_max_tresca_x_over_a: float | None = quantity("x/a of the largest Tresca stress", "1")
    stress_max_tresca_z_over_a: float | None = quantity("z/a of the largest Tresca stress", "1")
    stress_max_tresca_body: str | None = text("body of the largest Tresca stress")
    stress_max_tau_xz_range: float | None = quantity("largest orthogonal shear range over a rolling pass", "stress")
    stress_max_tau_xz_range_x_over_a: float | None = quantity("x/a of the largest orthogonal shear range", "1")
    stress_max_tau_xz_range_z_over_a: float | None = quantity("z/a of the largest orthogonal shear range", "1")
    stress_max_tau_xz_range_body: str | None = text("body of the largest orthogonal shear range")
    stress_max_sigma_1: float | None = quantity("largest principal stress (tension > 0)", "stress")
    stress_max_sigma_1_x_over_a: float | None = quantity("x/a of the largest principal stress", "1")
    stress_max_sigma_1_z_over_a: float | None = quantity("z/a of the largest principal stress", "1")
    stress_max_sigma_1_body: str | None = text("body of the largest principal stress")
    stress_max_surface_tension: float | None = quantity("largest surface sigma_xx (tension > 0)", "stress")
    stress_max_surface_tension_x_over_a: float | None = quantity("x/a of the largest surface tension", "1")
    stress_max_surface_tension_z_over_a: float | None = quantity("z/a of the largest surface tension (0)", "1")
    stress_max_surface_tension_body: str | None = text("body of the largest surface tension")
    stress_max_bond_shear: float | None = quantity("largest |tau_xz| on the bond line", "stress")
    stress_max_bond_shear_x_over_a: float | None = quantity("x/a of the largest bond shear", "1")
    stress_max_bond_shear_z_over_a: float | None = quantity("z/a of the largest bond shear (the bond depth)", "1")
    stress_max_bond_shear_body: str | None = text("body of the largest bond shear")
    stress_max_bond_tension: float | None = quantity("largest sigma_zz on the bond line (tension > 0)", "stress")
    stress_max_bond_tension_x_over_a: float | None = quantity("x/a of the largest bond tension", "1")
    stress_max_bond_tension_z_over_a: float | None = quantity("z/a of the largest bond tension (the bond depth)", "1")
    stress_max_bond_tension_body: str | None = text("body of the largest bond tension")


@dataclass(kw_only=True)
class Sensitivities:
    """Derivatives of the converged solve (:mod:`rolling_cli.solver.sensitivity`): implicit
    differentiation at the final node states, P-derivatives of half-space pairs by homogeneity."""

    dQ_dxi: float | None = quantity("creep coefficient dQ/dxi at fixed mu and P", "force/length")
    dQ_dmu: float | None = quantity(
        "dQ/dmu at fixed creepage and P (a slip-speed law: d/dmu_static with the law scaled as a whole)",
        "force/length",
    )
    dQ_dP: float | None = quantity("dQ/dP at fixed creepage and mu", "1")
    dxi_dQ: float | None = quantity("dxi/dQ at fixed mu and P", "1/(force/length)")
    dxi_dmu: float | None = quantity(
        "dxi/dmu at fixed Q and P (a slip-speed law: d/dmu_static with the law scaled as a whole)", "1"
    )
    dxi_dP: float | None = quantity("dxi/dP at fixed Q and mu", "1/(force/length)")
    da_dP: float | None = quantity(
        "d(contact half-width)/dP, the case's tangential control held", "length/(force/length)"
    )
    dp0_dP: float | None = quantity(
        "d(peak pressure max|p_n|)/dP, the case's tangential control held", "stress/(force/length)"
    )
    dQ_db: float | None = quantity(
        "dQ/d(layer thickness b) at fixed creepage, mu and P (central difference of the influence in b)", "stress"
    )
    dxi_db: float | None = quantity(
        "dxi/d(layer thickness b) at fixed Q, mu and P (central difference of the influence in b)", "1/(length)"
    )
    dQ_dV: float | None = quantity(
        "dQ/d(rolling speed |V|) at fixed creepage, friction law and P (slip-speed friction laws)",
        "force/length/(length/time)",
    )
    dxi_dV: float | None = quantity(
        "dxi/d(rolling speed |V|) at fixed Q, friction law and P (slip-speed friction laws)", "1/(length/time)"
    )


@dataclass(kw_only=True)
class RollingResistance:
    """Viscoelastic rolling (:mod:`rolling_cli.model.resistance`); recorded only when a body is viscoelastic."""

    rolling_resistance_moment: float | None = quantity(
        "rolling-resistance moment of the pair, sgn(V) sum w p_n x (resisting > 0)", "moment/length"
    )
    rolling_resistance_moment_a: float | None = quantity(
        "moment of the contact tractions about A's shaft against its rotation, sgn(V) (sum w p_n x - R_A Q) "
        "(NaN for a flat)",
        "moment/length",
    )
    rolling_resistance_moment_b: float | None = quantity(
        "moment of the contact tractions about B's shaft against its rotation, sgn(V) (sum w p_n x + R_B Q) "
        "(NaN for a flat)",
        "moment/length",
    )
    rolling_resistance_coefficient: float | None = quantity(
        "rolling-resistance coefficient M / (P R*); for a finite roller on a rigid flat F_rr / P "
        "(rolling_resistance_force)",
        "1",
    )
    rolling_resistance_force: float | None = quantity(
        "finite roller on a rigid flat: rolling-resistance force of the power balance, "
        "sgn(V) [sum w p_n tan(theta) (1 + eps) + sum w (p_n u + p_t w) / R] (= losses / |V| + xi Q)",
        "force/length",
    )
    shaft_torque_displacement: float | None = quantity(
        "finite roller on a rigid flat: the shaft torque's part from the tractions' displaced points, "
        "-sum w (w p_t + u p_n) (the torque transmitted is R Q plus this)",
        "moment/length",
    )
    pressure_centroid: float | None = quantity("centroid of the pressure, sum w (-p_n) x / P", "length")
    pressure_shift: float | None = quantity("shift of the pressure centroid towards the leading edge", "length")
    hysteresis_power: float | None = quantity(
        "hysteresis power of the bodies per unit rolling speed and axial length (loss compliance)", "force/length"
    )


#: The groups, in the order the file lists their variables.
GROUPS = (
    Provenance,
    Convergence,
    Loads,
    Friction,
    Contact,
    Sensitivities,
    RollingResistance,
    Model,
    Timings,
    Adaptive,
    ErrorEstimate,
    StressMaxima,
    RollingResistance,
)


def declared() -> dict[str, Quantity]:
    """Every declared quantity by name, in group order."""
    return {f.name: f.metadata["quantity"] for group in GROUPS for f in dataclasses.fields(group)}
