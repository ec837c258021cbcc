"""Creep-force tables: the file and its interpolant (issue 24 items 2-3), for use inside other programs.

A table (``rollc table CASE -o table.h5``, built by :mod:`rolling_cli.study.tabulate`)
holds Q/(mu P) and its derivative at nodes of one axis, the creepage normalised
as u = xi R*/(mu a) with its sign (a the case's contact scale, the Hertz
half-width under a load on two half-spaces), sampled until the cubic Hermite
interpolant's error estimate is below the table's tolerance.

:func:`load` returns a :class:`Table`: a vectorised callable ``table(u)`` ->
Q/(mu P), numpy only (neither the solver nor h5py is used by the call; h5py
only reads the file), with its ``domain``, ``tolerance`` and ``error_bound``.
A query outside the domain (or NaN) raises ValueError: the table never
extrapolates. Example::

    from rolling_cli import table
    creep_force = table.load("carter_table.h5")
    q_over_mu_p = creep_force(np.array([-0.2, 0.0, 0.3]))

The file (HDF5): datasets ``creep_normalised`` (the nodes u, increasing),
``q_over_mu_p`` and ``dq_over_mu_p_du`` at the nodes, ``interval_error`` (the
error estimate of each interval); root attributes ``format`` =
"rolling_cli.table", ``format_version``, ``tolerance``, ``error_bound`` (the
largest estimate), ``domain`` (lo, hi), ``creep_scale`` mu a/R*, ``mu``,
``half_width`` a, ``radius`` R*, ``load`` P, ``cases`` (solves), the case as
TOML (``case_toml``) and provenance.

With a second axis (``rollc table --mu LO:HI``) :func:`load` returns a
:class:`FrictionTable`, called as ``table(u, mu)``: rows at the friction nodes
``friction_nodes``, stored end to end (``row_start`` their offsets) with the
slope in mu ``dq_over_mu_p_dmu`` besides; ``friction_interval_error`` the
estimate of each interval in mu.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

FORMAT = "rolling_cli.table"
FORMAT_VERSION = 1

#: Datasets: name -> long name (every one is dimensionless, units "1").
DATASETS = {
    "creep_normalised": "creepage normalised as xi R*/(mu a), with its sign",
    "q_over_mu_p": "Q/(mu P) at the node",
    "dq_over_mu_p_du": "d(Q/(mu P))/d(xi R*/(mu a)) at the node, from the sensitivity dQ/dxi",
}


@dataclass(frozen=True)
class Table:
    """A one-axis creep-force table and its cubic Hermite interpolant.

    ``nodes`` u (increasing), ``values`` Q/(mu P) and ``slopes`` d(Q/(mu P))/du at
    them; ``tolerance`` the requested interpolation error and ``error_bound`` the
    largest estimate reached (both in Q/(mu P)); ``attributes`` the file's others.
    """

    nodes: np.ndarray
    values: np.ndarray
    slopes: np.ndarray
    tolerance: float
    error_bound: float
    attributes: dict = field(default_factory=dict)

    @property
    def domain(self) -> tuple[float, float]:
        """(lo, hi): the normalised creepages u the table covers."""
        return float(self.nodes[0]), float(self.nodes[-1])

    def __call__(self, creep_normalised) -> np.ndarray:
        """Q/(mu P) [-] at the normalised creepages u = xi R*/(mu a) (any shape); ValueError outside
        the domain or for NaN."""
        u = np.asarray(creep_normalised, dtype=float)
        return hermite(self.nodes, self.values, self.slopes, u)


def hermite(nodes: np.ndarray, values: np.ndarray, slopes: np.ndarray, u: np.ndarray) -> np.ndarray:
    """The piecewise cubic Hermite interpolant through (nodes, values, slopes) at ``u`` (any shape);
    ValueError for a point outside [nodes[0], nodes[-1]] or NaN."""
    lo, hi = nodes[0], nodes[-1]
    inside = (u >= lo) & (u <= hi)  # False for NaN
    if not np.all(inside):
        bad = float(u[~inside].ravel()[0])
        raise ValueError(f"creepage xi R*/(mu a) = {bad:g} outside the table's domain [{lo:g}, {hi:g}]")
    k = np.clip(np.searchsorted(nodes, u, side="right") - 1, 0, nodes.size - 2)
    x0 = nodes[k]
    h = nodes[k + 1] - x0
    t = (u - x0) / h
    t2 = t * t
    t3 = t2 * t
    return (
        (2 * t3 - 3 * t2 + 1) * values[k]
        + (t3 - 2 * t2 + t) * h * slopes[k]
        + (-2 * t3 + 3 * t2) * values[k + 1]
        + (t3 - t2) * h * slopes[k + 1]
    )


class TableRow(NamedTuple):
    """One row of a two-axis table: friction ``mu``, the nodes u, Q/(mu P) there, and its slopes in u
    and in mu (at fixed u)."""

    mu: float
    nodes: np.ndarray
    values: np.ndarray
    slopes: np.ndarray
    mu_slopes: np.ndarray


def between(low: TableRow, high: TableRow, u: np.ndarray, mu: np.ndarray) -> np.ndarray:
    """Q/(mu P) at (u, mu) between two rows: each row's cubic Hermite in u gives the values at u,
    its slopes in mu interpolated linearly in u, then a cubic Hermite in mu (ValueError for a u
    outside either row)."""
    values = [hermite(row.nodes, row.values, row.slopes, u) for row in (low, high)]
    slopes = [np.interp(u, row.nodes, row.mu_slopes) for row in (low, high)]
    h = high.mu - low.mu
    t = (mu - low.mu) / h
    t2 = t * t
    t3 = t2 * t
    return (
        (2 * t3 - 3 * t2 + 1) * values[0]
        + (t3 - 2 * t2 + t) * h * slopes[0]
        + (-2 * t3 + 3 * t2) * values[1]
        + (t3 - t2) * h * slopes[1]
    )


@dataclass(frozen=True)
class FrictionTable:
    """A two-axis creep-force table: rows over u = xi R*/(mu a) at friction nodes ``rows[k].mu``.

    ``table(u, mu)`` gives Q/(mu P) (any shapes that broadcast); ValueError outside the domain
    ((u_lo, u_hi), (mu_lo, mu_hi)) or for NaN. ``friction_error`` is the error estimate of each
    interval in mu (the mid-row's largest miss), ``error_bound`` the largest estimate in u or mu.
    """

    rows: tuple[TableRow, ...]
    tolerance: float
    error_bound: float
    friction_error: np.ndarray
    attributes: dict = field(default_factory=dict)

    @property
    def friction(self) -> np.ndarray:
        """The friction coefficients of the rows (increasing)."""
        return np.array([row.mu for row in self.rows])

    @property
    def domain(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """((u_lo, u_hi), (mu_lo, mu_hi))."""
        first = self.rows[0].nodes
        return (float(first[0]), float(first[-1])), (self.rows[0].mu, self.rows[-1].mu)

    def __call__(self, creep_normalised, mu) -> np.ndarray:
        """Q/(mu P) [-] at (u, mu); ValueError outside the domain or for NaN."""
        u, m = np.broadcast_arrays(np.asarray(creep_normalised, dtype=float), np.asarray(mu, dtype=float))
        friction = self.friction
        inside = (m >= friction[0]) & (m <= friction[-1])
        if not np.all(inside):
            bad = float(m[~inside].ravel()[0])
            raise ValueError(f"mu = {bad:g} outside the table's domain [{friction[0]:g}, {friction[-1]:g}]")
        k = np.clip(np.searchsorted(friction, m, side="right") - 1, 0, friction.size - 2)
        out = np.empty(u.shape)
        for row in np.unique(k):  # a loop over the rows (a few), each a vectorised evaluation
            pick = k == row
            out[pick] = between(self.rows[row], self.rows[row + 1], u[pick], m[pick])
        return out


def load(path: str) -> Table | FrictionTable:
    """The table of a file written by ``rollc table``: a :class:`Table`, or with ``--mu`` a
    :class:`FrictionTable` (ValueError naming the file when it is not one)."""
    import h5py

    with h5py.File(path, "r") as handle:
        if handle.attrs.get("format") != FORMAT:
            raise ValueError(f"{path}: not a rolling_cli table (format {handle.attrs.get('format')!r})")
        if "friction_nodes" in handle:
            return _load_friction(handle)
        nodes = np.asarray(handle["creep_normalised"][()], dtype=float)
        values = np.asarray(handle["q_over_mu_p"][()], dtype=float)
        slopes = np.asarray(handle["dq_over_mu_p_du"][()], dtype=float)
        attributes = {key: _plain(value) for key, value in handle.attrs.items()}
    if nodes.size < 2 or not np.all(np.diff(nodes) > 0.0):
        raise ValueError(f"{path}: the table's nodes are not increasing")
    return Table(nodes, values, slopes, float(attributes["tolerance"]), float(attributes["error_bound"]), attributes)


def _plain(value):
    if isinstance(value, bytes):
        return value.decode()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    return value


def write(path: str, table: Table, interval_error: np.ndarray) -> None:
    """Write ``table`` (its attributes at the root, ``interval_error`` per interval) to HDF5 ``path``."""
    import h5py

    with h5py.File(path, "w") as handle:
        arrays = {
            "creep_normalised": table.nodes,
            "q_over_mu_p": table.values,
            "dq_over_mu_p_du": table.slopes,
        }
        for name, values in arrays.items():
            dataset = handle.create_dataset(name, data=np.asarray(values, dtype=float))
            dataset.attrs["long_name"] = DATASETS[name]
            dataset.attrs["units"] = "1"
        dataset = handle.create_dataset("interval_error", data=np.asarray(interval_error, dtype=float))
        dataset.attrs["long_name"] = "interpolation error estimate of each interval, in Q/(mu P)"
        dataset.attrs["units"] = "1"
        handle.attrs["format"] = FORMAT
        handle.attrs["format_version"] = FORMAT_VERSION
        handle.attrs["tolerance"] = table.tolerance
        handle.attrs["error_bound"] = table.error_bound
        handle.attrs["domain"] = np.array(table.domain)
        for key, value in table.attributes.items():
            handle.attrs[key] = value


def _load_friction(handle) -> FrictionTable:
    """The two-axis table of an open file (rows stored end to end, ``row_start`` their offsets)."""
    start = np.asarray(handle["row_start"][()], dtype=int)
    friction = np.asarray(handle["friction_nodes"][()], dtype=float)
    columns = [np.asarray(handle[name][()], dtype=float) for name in ROW_COLUMNS]
    rows = tuple(
        TableRow(float(friction[k]), *(column[start[k] : start[k + 1]] for column in columns))
        for k in range(friction.size)
    )
    attributes = {key: _plain(value) for key, value in handle.attrs.items()}
    error = np.asarray(handle["friction_interval_error"][()], dtype=float)
    return FrictionTable(rows, float(attributes["tolerance"]), float(attributes["error_bound"]), error, attributes)


#: The per-node columns of a two-axis table's rows, in TableRow's order after mu.
ROW_COLUMNS = ("creep_normalised", "q_over_mu_p", "dq_over_mu_p_du", "dq_over_mu_p_dmu")


def write_friction(path: str, made: FrictionTable, row_errors: list[np.ndarray]) -> None:
    """Write a two-axis table (rows end to end; ``row_errors`` each row's interval estimates) to HDF5."""
    import h5py

    long_names = {
        **DATASETS,
        "dq_over_mu_p_dmu": "d(Q/(mu P))/dmu at fixed xi R*/(mu a), from dQ/dmu and dQ/dxi",
        "friction_nodes": "coefficient of friction mu of each row",
        "row_start": "offset of each row's first node (and the end), for the per-node columns",
        "interval_error": "interpolation error estimate of each interval in u, row by row, in Q/(mu P)",
        "friction_interval_error": "interpolation error estimate of each interval in mu, in Q/(mu P)",
    }
    sizes = np.array([row.nodes.size for row in made.rows])
    arrays = {
        name: np.concatenate([getattr(row, field_name) for row in made.rows])
        for name, field_name in zip(ROW_COLUMNS, ("nodes", "values", "slopes", "mu_slopes"), strict=True)
    }
    arrays["friction_nodes"] = made.friction
    arrays["row_start"] = np.concatenate([[0], np.cumsum(sizes)])
    arrays["interval_error"] = np.concatenate(row_errors)
    arrays["friction_interval_error"] = made.friction_error
    with h5py.File(path, "w") as handle:
        for name, values in arrays.items():
            dataset = handle.create_dataset(name, data=values)
            dataset.attrs["long_name"] = long_names[name]
            dataset.attrs["units"] = "1"
        handle.attrs["format"] = FORMAT
        handle.attrs["format_version"] = FORMAT_VERSION
        handle.attrs["tolerance"] = made.tolerance
        handle.attrs["error_bound"] = made.error_bound
        (u_lo, u_hi), (mu_lo, mu_hi) = made.domain
        handle.attrs["domain"] = np.array([u_lo, u_hi])
        handle.attrs["friction_domain"] = np.array([mu_lo, mu_hi])
        handle.attrs["axes"] = "creep_normalised, mu"
        for key, value in made.attributes.items():
            handle.attrs[key] = value
