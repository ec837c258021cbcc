"""The case-file schema: one frozen dataclass per TOML table.

Each field carries its documentation, units and allowed values in its
metadata; :mod:`rolling_cli.case.validate` reads them to convert and check a
TOML document and to report errors by dotted key. Defaults are the documented
defaults of the README. Units are whatever consistent system the user chooses
(the README recommends N, mm and MPa = N/mm^2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from ..errors import CaseError
from ..influence.choice import MODELS
from .given import given

#: Magnitudes allowed for dimensional inputs (lengths, moduli, loads, penalties)
#: in any consistent unit system. Any practical unit system fits (steel in Pa
#: and m: E = 2e11, a = 1e-3); the solver forms products and squares of a few
#: of them (p0^2 in the merit, E*/a in the penalty), which stay far from the
#: double-precision overflow (1e308) and underflow (1e-308) within these limits.
SMALLEST = 1e-30
LARGEST = 1e30

#: The default bore of an elastic core under a cover (``core_young``), as a fraction of the outer
#: radius: a solid core on a thin axle (the core's approach is then measured from that axle).
CORE_BORE = 0.05

#: Friction coefficients: 0 (frictionless) or MU_SMALLEST..MU_LARGEST. With
#: dissimilar bodies the adhesion slip is the difference of the coupling term
#: B_tn p_n, of order (a/R), and terms of order mu (a/R): below mu ~ 1e-6 that
#: difference is lost to rounding (relative error eps/mu > 1e-10, the default
#: tolerance). No real pair has mu > 100 (that is full adhesion already).
MU_SMALLEST = 1e-6
MU_LARGEST = 100.0


def spec(default: Any = None, *, doc: str, required: bool = False, **rules: Any) -> Any:
    """A dataclass field with validation rules in its metadata.

    Rules: ``kind`` ("float", "int", "str", "bool", "float_or_auto"),
    ``choices``, ``gt``/``ge``/``lt``/``le`` bounds, ``allow_inf``,
    ``zero_or_ge`` (0 or at least this), ``max_length`` (strings; control
    characters are never allowed).
    """
    metadata = {"doc": doc, "required": required, **rules}
    return field(default=default, metadata=metadata)


def _prony(value: Any, key: str, file: str | None) -> tuple:
    """[bodies.X] prony: [[E_i, tau_i], ...] (:func:`rolling_cli.model.viscoelastic.prony_terms`)."""
    from ..model.viscoelastic import prony_terms

    return prony_terms(value, key, file)


@dataclass(frozen=True)
class Body:
    """One cylinder: [bodies.A] (upper) or [bodies.B] (lower)."""

    kind: str = spec("elastic", doc="body model", kind="str", choices=("elastic", "rigid", "layered", "viscoelastic"))
    radius: float = spec(
        None,
        doc="cylinder (outer) radius [length]; inf for a flat",
        kind="float",
        ge=SMALLEST,
        le=LARGEST,
        allow_inf=True,
        required=True,
    )
    young: float | None = spec(
        None,
        doc="Young's modulus E [stress] (elastic, layered; viscoelastic: the glassy modulus E_g)",
        kind="float",
        ge=SMALLEST,
        le=LARGEST,
    )
    poisson: float | None = spec(
        None, doc="Poisson's ratio nu (elastic, layered, viscoelastic: constant in time)", kind="float", ge=0.0, le=0.5
    )
    layer_thickness: float | None = spec(
        None, doc="layer thickness b [length] (layered; b < radius)", kind="float", ge=SMALLEST, le=LARGEST
    )
    relaxed_young: float | None = spec(
        None,
        doc="relaxed (long-time) modulus E_r <= young [stress] (viscoelastic SLS)",
        kind="float",
        gt=0.0,
        le=LARGEST,
    )
    creep_time: float | None = spec(
        None,
        doc="creep (retardation) time tau_c of J(t) = 1/E_g + (1/E_r - 1/E_g)(1 - exp(-t/tau_c)) [time] "
        "(viscoelastic SLS)",
        kind="float",
        gt=0.0,
        le=LARGEST,
    )
    prony: tuple | None = spec(
        None,
        doc="relaxation Prony series [[E_i, tau_i], ...], E(t) = E_r + sum E_i exp(-t/tau_i), E_r = young - sum E_i "
        "[stress, time] (viscoelastic, instead of relaxed_young and creep_time)",
        convert=_prony,
    )
    viscoelastic: bool = spec(
        False,
        doc="a viscoelastic layer (layered; its creep compliance from young = E_g and relaxed_young and "
        "creep_time, or prony, as kind = viscoelastic)",
        kind="bool",
    )
    shape: str = spec(
        "half-space",
        doc="what the influence model represents: the half-space near the contact, or the whole cross-section",
        kind="str",
        choices=("half-space", "cylinder"),
    )
    inner_radius: float | None = spec(
        None,
        doc="bore radius r_i [length], bonded to a rigid shaft (shape = cylinder, elastic; 0 < r_i < radius; "
        "layered with core_young: the elastic core's bore, r_i < radius - layer_thickness, default "
        "CORE_BORE x radius)",
        kind="float",
        ge=SMALLEST,
        le=LARGEST,
    )
    core_young: float | None = spec(
        None,
        doc="Young's modulus of an elastic core under the cover [stress] (layered, shape = cylinder; absent: "
        "a rigid core)",
        kind="float",
        ge=SMALLEST,
        le=LARGEST,
    )
    core_poisson: float | None = spec(
        None,
        doc="Poisson's ratio of the elastic core (with core_young; -1 < nu <= 0.5)",
        kind="float",
        gt=-1.0,
        le=0.5,
    )

    @property
    def rigid(self) -> bool:
        return self.kind == "rigid"

    @property
    def finite(self) -> bool:
        """True for ``shape = "cylinder"``: the whole cross-section is modelled (:mod:`rolling_cli.model.shapes`)."""
        return self.shape == "cylinder"

    @property
    def body_shape(self):
        """The body's :data:`~rolling_cli.model.shapes.BodyShape`: ``HalfSpace()``, or the ``Cylinder``
        between :attr:`core_radius` and ``radius`` (a rigid body: ``None``)."""
        from ..model.shapes import Cylinder, HalfSpace

        if self.rigid:
            return None
        return Cylinder(float(self.radius), self.core_radius) if self.finite else HalfSpace()

    @property
    def core_radius(self) -> float:
        """The radius of the rigid shaft or core of a finite cylinder [length]: the bore
        (elastic) or radius - layer_thickness (layered)."""
        if self.kind == "layered":
            return float(self.radius) - float(given(self.layer_thickness, "layer_thickness"))
        return float(given(self.inner_radius, "inner_radius"))

    @property
    def elastic_core(self) -> bool:
        """True for a finite layered cylinder whose cover is bonded to an elastic core (``core_young``)."""
        return self.kind == "layered" and self.finite and self.core_young is not None

    @property
    def core_bore(self) -> float:
        """The elastic core's bore r_i [length], bonded to the rigid shaft: ``inner_radius``, by
        default ``CORE_BORE`` x radius (a solid core on a thin axle)."""
        if self.inner_radius is not None:
            return float(self.inner_radius)
        return CORE_BORE * float(self.radius)

    @property
    def modulus(self) -> float:
        """Young's modulus for the closed forms: inf for a rigid body, the relaxed modulus E_r of a
        viscoelastic one (the mesh scale: its contact is the widest) [stress]."""
        if self.rigid:
            return math.inf
        if self.kind == "viscoelastic" or (self.kind == "layered" and self.viscoelastic):
            from ..model.viscoelastic import relaxed_modulus

            return relaxed_modulus(self)
        return given(self.young, "young")

    @property
    def ratio(self) -> float:
        """Poisson's ratio for the closed forms (0 for a rigid body: it then multiplies 1/inf)."""
        if self.rigid:
            return 0.0
        return given(self.poisson, "poisson")


@dataclass(frozen=True)
class Bodies:
    A: Body = spec(None, doc="upper cylinder", kind="table", required=True)
    B: Body = spec(None, doc="lower cylinder", kind="table", required=True)


#: ``friction.law`` values: Coulomb (constant) and CONTACT's slip-velocity laws (:mod:`rolling_cli.model.friction`).
FRICTION_LAWS = ("constant", "linear", "rational", "exponential", "polach")


@dataclass(frozen=True)
class Friction:
    """Coulomb friction (``mu``) or a law mu(s_a) of the slip speed s_a = |V| |s_t|
    (:mod:`rolling_cli.model.friction`); a velocity law's ``mu`` is set to ``mu_static`` on loading."""

    law: str = spec("constant", doc="friction law mu(s_a)", kind="str", choices=FRICTION_LAWS)
    mu: float = spec(  # None in a file with a velocity law; set to mu_static on loading (always a float then)
        None,
        doc='Coulomb friction coefficient (0: frictionless); law = "constant" only',
        kind="float",
        ge=0.0,
        zero_or_ge=MU_SMALLEST,
        le=MU_LARGEST,
    )
    mu_static: float | None = spec(
        None, doc="mu at rest, mu(0) (velocity laws)", kind="float", ge=MU_SMALLEST, le=MU_LARGEST
    )
    mu_kinetic: float | None = spec(
        None,
        doc="mu at high slip speed, mu(inf) (linear, rational, exponential; <= mu_static)",
        kind="float",
        ge=MU_SMALLEST,
        le=MU_LARGEST,
    )
    slip_velocity_half: float | None = spec(
        None,
        doc="s_h: slip speed halving mu - mu_kinetic [length/time] (linear, rational, exponential)",
        kind="float",
        gt=0.0,
        le=LARGEST,
    )
    polach_a: float | None = spec(None, doc="Polach's A = mu(inf)/mu_static (polach)", kind="float", gt=0.0, le=1.0)
    polach_b: float | None = spec(None, doc="Polach's B [time/length] (polach)", kind="float", ge=0.0, le=LARGEST)


#: The keys each velocity law needs (``mu`` belongs to the constant law alone).
LAW_KEYS = {
    "constant": ("mu",),
    "linear": ("mu_static", "mu_kinetic", "slip_velocity_half"),
    "rational": ("mu_static", "mu_kinetic", "slip_velocity_half"),
    "exponential": ("mu_static", "mu_kinetic", "slip_velocity_half"),
    "polach": ("mu_static", "polach_a", "polach_b"),
}


@dataclass(frozen=True)
class Normal:
    """Exactly one of ``load`` and ``overlap``."""

    load: float | None = spec(None, doc="normal load P [force/length]", kind="float", ge=SMALLEST, le=LARGEST)
    overlap: float | None = spec(
        None, doc="imposed rigid overlap [length] (BEM only)", kind="float", ge=SMALLEST, le=LARGEST
    )


@dataclass(frozen=True)
class Tangential:
    """At most one key; none means free rolling (Q = 0)."""

    q_over_mu_p: float | None = spec(None, doc="Q / (mu P)", kind="float")
    q_over_p: float | None = spec(None, doc="Q / P", kind="float")
    load: float | None = spec(
        None, doc="tangential force Q on body A [force/length]", kind="float", ge=-LARGEST, le=LARGEST
    )
    creep: float | None = spec(None, doc="creepage xi = (V_A - V_B)/|V|", kind="float", ge=-1.0, le=1.0)

    def control(self) -> tuple[str, float]:
        """(kind, value) of the prescribed tangential quantity; ("load", 0) if none."""
        for name in ("q_over_mu_p", "q_over_p", "load", "creep"):
            value = getattr(self, name)
            if value is not None:
                return name, float(value)
        return "load", 0.0


@dataclass(frozen=True)
class Rolling:
    direction: int = spec(-1, doc="sign of the rolling speed V (the paper uses V < 0)", kind="int", choices=(-1, 1))
    speed: float | None = spec(
        None,
        doc="rolling speed |V| [length/time] (required by a viscoelastic body or a slip-speed friction law)",
        kind="float",
        gt=0.0,
        le=LARGEST,
    )


@dataclass(frozen=True)
class Discretization:
    influence: str = spec(
        "auto", doc="influence model (auto: half-plane where exact, else BEM)", kind="str", choices=MODELS
    )
    contact_elements: int = spec(200, doc="elements over the potential contact zone", kind="int", ge=2, le=50000)
    zone: float = spec(1.5, doc="potential zone half-width / Hertz a", kind="float", gt=1.0, le=20.0)
    element: str = spec(
        "quadratic",
        doc="traction interpolation (constant: half-plane only)",
        kind="str",
        choices=("quadratic", "constant"),
    )
    slip_derivative: str = spec("fd", doc="slip derivative scheme", kind="str", choices=("fd", "element"))
    block_width: float = spec(100.0, doc="BEM half-space truncation: half-width / a", kind="float", gt=2.0, le=10000.0)
    block_depth: float = spec(
        100.0,
        doc="BEM half-space: truncation depth / a, the overlap's reference depth",
        kind="float",
        gt=1.0,
        le=10000.0,
    )
    layer_length: float = spec(
        10.0, doc="BEM layer: free length beyond the zone / layer thickness", kind="float", gt=0.5, le=1000.0
    )
    tolerance: float | None = spec(
        None,
        doc="requested maximum traction error / (mu p0) (/ p0 when frictionless): adaptive meshes from "
        "contact_elements on; none: the fixed mesh",
        kind="float",
        ge=1e-5,
        le=0.5,
    )
    max_refinements: int = spec(
        10, doc="adaptive meshes: most refinements after the first mesh", kind="int", ge=0, le=50
    )


@dataclass(frozen=True)
class Solver:
    tolerance: float = spec(1e-10, doc="relative residual tolerance", kind="float", ge=1e-14, le=1e-3)
    max_iterations: int = spec(100, doc="Newton iteration cap", kind="int", ge=1, le=100000)
    penalty: Any = spec("auto", doc='penalty r_t [stress] or "auto"', kind="float_or_auto", ge=SMALLEST, le=LARGEST)
    branch: str = spec(
        "auto",
        doc="creep-force branch of a force-controlled solve with a falling friction law",
        kind="str",
        choices=("auto", "low-slip", "high-slip"),
    )


@dataclass(frozen=True)
class Effects:
    coupling: str = spec("auto", doc="normal-tangential coupling", kind="str", choices=("auto", "on", "off"))


def _grid_points(value: Any, key: str, file: str | None) -> tuple[int, int]:
    """[stresses] points: two integers, nx in 3..4001 and nz in 2..4001, at most 4e6 points in all."""
    allowed = "[nx, nz], integers 3 <= nx <= 4001 and 2 <= nz <= 4001, nx nz <= 4000000"
    ok = isinstance(value, (list, tuple)) and len(value) == 2 and all(type(v) is int for v in value)
    if not ok or not (3 <= value[0] <= 4001 and 2 <= value[1] <= 4001 and value[0] * value[1] <= 4_000_000):
        raise CaseError(f"{key} = {value!r}: not a valid field grid; allowed: {allowed}", file=file, key=key)
    return (value[0], value[1])


def _body_labels(value: Any, key: str, file: str | None) -> tuple[str, ...]:
    """[stresses] bodies: a non-empty list of distinct "A" and "B"."""
    ok = isinstance(value, (list, tuple)) and value and all(v in ("A", "B") for v in value)
    ok = ok and len(set(value)) == len(value)
    if not ok:
        raise CaseError(
            f'{key} = {value!r}: not a list of bodies; allowed: ["A"], ["B"] or ["A", "B"]', file=file, key=key
        )
    return tuple(value)


@dataclass(frozen=True)
class Stresses:
    """Subsurface stress fields; computed only when the case has a [stresses] table.

    Two more field rules serve it (:mod:`~rolling_cli.case.validate`): ``convert``, a function
    (value, dotted key, file) -> value for the lists, and ``optional`` on the Case field: None when absent.
    """

    depth: float = spec(
        3.0,
        doc="field depth below each surface / a (a layer or a finite cylinder: down to its bond line at most)",
        kind="float",
        gt=0.0,
        le=100.0,
    )
    points: tuple = spec((201, 101), doc="field grid points [nx, nz]", convert=_grid_points)
    bodies: tuple = spec(
        ("A", "B"), doc='bodies whose fields are computed ("A", "B"; rigid ones are skipped)', convert=_body_labels
    )


@dataclass(frozen=True)
class Units:
    length: str = spec("mm", doc="length unit name (labels only)", kind="str", max_length=40)
    force: str = spec("N", doc="force unit name (labels only)", kind="str", max_length=40)
    time: str = spec(
        "s", doc="time unit name (labels only: creep times; speeds are length/time)", kind="str", max_length=40
    )

    @property
    def stress(self) -> str:
        return f"{self.force}/{self.length}^2"

    @property
    def line_force(self) -> str:
        return f"{self.force}/{self.length}"


@dataclass(frozen=True)
class Output:
    file: str | None = spec(None, doc="result file (default: the case name with .h5)", kind="str", max_length=4096)
    layer_derivative: bool = spec(
        False,
        doc="also dQ/db and dxi/db of the layered body (b its thickness): two more BEM builds at b +- 1e-4 b",
        kind="bool",
    )


@dataclass(frozen=True)
class Case:
    """A resolved case. ``source`` is the file it came from (or None)."""

    bodies: Bodies = spec(None, doc="the two cylinders", kind="table", required=True)
    friction: Friction = spec(None, doc="friction", kind="table", required=True)
    normal: Normal = spec(None, doc="normal loading", kind="table", required=True)
    tangential: Tangential = spec(None, doc="tangential loading", kind="table")
    rolling: Rolling = spec(None, doc="rolling", kind="table")
    discretization: Discretization = spec(None, doc="discretisation", kind="table")
    solver: Solver = spec(None, doc="solver", kind="table")
    effects: Effects = spec(None, doc="effect selection", kind="table")
    units: Units = spec(None, doc="unit names", kind="table")
    output: Output = spec(None, doc="output", kind="table")
    stresses: Stresses | None = spec(None, doc="subsurface stresses (only when given)", kind="table", optional=True)
    title: str | None = spec(None, doc="case title", kind="str", max_length=1000)
    source: str | None = field(default=None, metadata={"internal": True})
