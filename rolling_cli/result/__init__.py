"""The result of one solve: plain arrays plus declared, typed scalars (:mod:`.quantities`).

Signs follow the paper: p_n <= 0 in compression; p_t is the traction that body
B exerts on body A, positive along +x, so Q = sum w p_t is the tangential force
on A; the slip s_t = (relative slip velocity of A on B) / |V|.
"""

from __future__ import annotations

import datetime
from collections.abc import Iterator, MutableMapping
from dataclasses import dataclass, field
from typing import Any, TypeVar

import numpy as np

from ..model.grid import node_cell_edges
from .quantities import (
    Adaptive,
    Contact,
    Convergence,
    ErrorEstimate,
    Friction,
    Loads,
    Model,
    Provenance,
    RollingResistance,
    Sensitivities,
    StressMaxima,
    Timings,
    declared,
)

T = TypeVar("T")

STATE_NAMES = {0: "separation", 1: "adhesion", 2: "slip"}

#: Dataset name -> (long name, unit key: "length" | "stress" | "1").
DATASETS = {
    "x": ("node position along the rolling direction", "length"),
    "p_n": ("normal traction (negative in compression)", "stress"),
    "p_t": ("tangential traction on body A (positive along +x)", "stress"),
    "delta_n": ("normal gap after deformation", "length"),
    "s_t": ("slip velocity of A relative to B divided by |V|", "1"),
    "state": ("contact state: 0 separation, 1 adhesion, 2 slip", "1"),
    "frictional_power": ("frictional power density per unit rolling speed, -p_t s_t (>= 0, dissipated)", "stress"),
    **{
        f"surface_{c}_{label}": (
            f"surface displacement of body {label} {what} (rolling_cli.influence.surface)",
            "length",
        )
        for label in ("A", "B")
        for c, what in (
            ("w", "into the body (its arc's inward normal for a finite cylinder), from the model's datum"),
            ("u", "along +x (a finite cylinder's arc tangent, B's in its mirror frame)"),
        )
    },
}


#: The surface displacement fields (:mod:`rolling_cli.influence.surface`); a sweep's rows leave them out.
SURFACES = ("surface_w_A", "surface_u_A", "surface_w_B", "surface_u_B")


class ScalarView(MutableMapping):
    """The recorded scalars of a result as a mapping (name -> value), read and written through.

    Reading gives the quantities recorded (not None); writing one sets the result's field;
    a name that is not declared in :mod:`rolling_cli.result.quantities` is refused
    (KeyError), so that nothing reaches a file without its unit and long name. A dotted
    key (``friction.mu``) reads and writes the result's :attr:`~Result.swept` values;
    iteration gives the recorded quantities only.
    """

    __slots__ = ("_result",)

    def __init__(self, result: Result) -> None:
        self._result = result

    def __getitem__(self, name: str) -> Any:
        if "." in name:
            return self._result.swept[name]
        value = getattr(self._result, name, None) if name in QUANTITIES else None
        if value is None:
            raise KeyError(name)
        return value

    def __setitem__(self, name: str, value: Any) -> None:
        if "." in name:
            self._result.swept[name] = value
            return
        if name not in QUANTITIES:
            raise KeyError(f"undeclared result quantity {name!r}: declare it in rolling_cli/result/quantities.py")
        setattr(self._result, name, value)

    def __delitem__(self, name: str) -> None:
        self[name]  # KeyError when not recorded
        if "." in name:
            del self._result.swept[name]
        else:
            setattr(self._result, name, None)

    def __iter__(self) -> Iterator[str]:
        values = vars(self._result)
        return (name for name in QUANTITIES if values.get(name) is not None)

    def __len__(self) -> int:
        return sum(1 for _ in self)


@dataclass
class Result(
    Provenance,
    Convergence,
    Loads,
    Friction,
    Contact,
    Sensitivities,
    Model,
    Timings,
    Adaptive,
    ErrorEstimate,
    StressMaxima,
    RollingResistance,
):
    """Arrays over the n contact nodes and the solve's declared scalars.

    Arrays: ``x``, ``weights`` [length]; ``p_n``, ``p_t`` [stress];
    ``delta_n`` [length]; ``s_t`` [-]; ``state`` (int8, :data:`STATE_NAMES`).
    Scalars: the fields of :mod:`rolling_cli.result.quantities` (loads P, Q
    [force/length], creepage, overlap [length] (NaN when undefined), Hertz a
    [length] and p0 [stress], ...), each None until recorded; :attr:`attributes`
    is the mapping of the recorded ones. ``swept``: the swept values of a sweep's
    case, by dotted key.
    """

    x: np.ndarray
    weights: np.ndarray
    p_n: np.ndarray
    p_t: np.ndarray
    delta_n: np.ndarray
    s_t: np.ndarray
    state: np.ndarray
    history: list[dict] = field(default_factory=list)
    reference: dict[str, np.ndarray] = field(default_factory=dict)
    case_toml: str | None = None  # the resolved input case as TOML; None: written from ``case`` when first read
    frictional_power: np.ndarray | None = None  # [stress], rolling_cli.stresses.power
    surface_w_A: np.ndarray | None = None  # [length] each deformable body's surface displacements,
    surface_u_A: np.ndarray | None = None  # rolling_cli.influence.surface (None: rigid, or an old file)
    surface_w_B: np.ndarray | None = None
    surface_u_B: np.ndarray | None = None
    stresses: dict = field(default_factory=dict)  # body label -> rolling_cli.stresses.compute.BodyStresses
    swept: dict[str, Any] = field(default_factory=dict)  # dotted key -> value, for a sweep's case
    case: object = field(default=None, repr=False, compare=False)  # the Case of the final mesh level, if solved here

    @property
    def attributes(self) -> ScalarView:
        """The recorded scalars, name -> value (:class:`ScalarView`: read and written through)."""
        return ScalarView(self)

    def record(self, **values: Any) -> None:
        """Record declared quantities (KeyError naming any undeclared one)."""
        self.attributes.update(values)

    def _get_case_toml(self) -> str:
        text = self.__dict__.get("_case_toml")
        if text is None:  # not given: written from the case solved, once
            case = self.__dict__.get("case")
            if case is None:
                text = ""
            else:
                from ..case import case_to_toml

                try:
                    text = case_to_toml(case)
                except AttributeError as err:
                    raise RuntimeError(f"the case of this result cannot be written as TOML: {err}") from err
            self.__dict__["_case_toml"] = text
        return text

    def _set_case_toml(self, text: str | None) -> None:
        self.__dict__["_case_toml"] = None if text is None else str(text)

    @property
    def units(self) -> dict[str, str]:
        """Unit names for "length", "stress", "force/length", "length/time" and "1"."""
        return {
            "length": self.unit_length or "length",
            "stress": self.unit_stress or "stress",
            "force/length": self.unit_line_force or "force/length",
            "length/time": f"{self.unit_length or 'length'}/{self.unit_time or 'time'}",
            "1": "1",
        }

    def zones(self) -> list[tuple[str, float, float]]:
        """Contiguous runs of one state as (name, x_start, x_end) [length], node cells included."""
        return state_zones(self.x, self.state)


#: Every declared scalar of a result by name (:mod:`rolling_cli.result.quantities`).
QUANTITIES = declared()


def recorded(value: T | None, name: str) -> T:
    """A quantity a stage needs: its value, or ValueError naming it when it was not recorded."""
    if value is None:
        raise ValueError(f"the result has no {name} recorded")
    return value


def state_zones(x: np.ndarray, state: np.ndarray) -> list[tuple[str, float, float]]:
    """Runs of equal state over the node cells [length], on any grid.

    A node's cell reaches half way to its neighbours (at the ends, half the end
    spacing beyond the end node): :func:`rolling_cli.model.grid.node_cell_edges`. On a
    uniform grid of spacing Delta that is [x_i - Delta/2, x_i + Delta/2].
    """
    if x.size == 0:
        return []
    cells = node_cell_edges(x)
    edges = np.flatnonzero(np.diff(state)) + 1
    starts = np.concatenate([[0], edges])
    ends = np.concatenate([edges, [x.size]])
    return [(STATE_NAMES[int(state[s])], float(cells[s]), float(cells[e])) for s, e in zip(starts, ends, strict=True)]


def utc_timestamp() -> str:
    """Now, ISO 8601 in UTC to the second: the ``created`` provenance attribute."""
    return datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")


def node_states(p_n: np.ndarray, stick: np.ndarray) -> np.ndarray:
    """int8 state per node: 0 separation (p_n = 0), 1 adhesion, 2 slip."""
    state = np.zeros(p_n.shape, dtype=np.int8)
    contact = p_n < 0.0
    state[contact & stick] = 1
    state[contact & ~stick] = 2
    return state


# The TOML of a solved case is written only when read (a sweep's cases never are: the sweep file
# holds the base case and the swept values): a property over the dataclass field, set after the
# class is made so that the field keeps its default (None: not written yet) in __init__. Where the
# input case differs from the final level's (a zone enlarged, an adaptive mesh), the pipeline sets
# the TOML itself.
Result.case_toml = property(Result._get_case_toml, Result._set_case_toml)  # type: ignore[assignment]
