"""The ``stresses`` subgroups of a result file: one per body, ``A`` and ``B``, of each case.

In a file they sit under the case's row, ``stresses/case_000000/A`` and
``stresses/case_000000/B`` (:mod:`rolling_cli.files.writer`; a single result also
links ``stresses/A`` and ``stresses/B`` to them); :func:`write_bodies` fills
one case's group.

Each subgroup holds the coordinates ``x`` and ``z`` (depth below that body's
surface, z >= 0, the case's length unit) and the (z, x) fields ``sigma_xx``,
``sigma_zz``, ``tau_xz``, ``sigma_yy``, ``von_mises``, ``tresca``,
``sigma_1``, ``sigma_2``, ``sigma_3``; ``tau_xz_range`` (z); the surface
stresses ``surface_sigma_xx``, ``surface_sigma_zz``, ``surface_tau_xz`` at
``surface_x`` (the contact nodes and the located contact edges and stick/slip
boundaries); for a layer
the bond line ``bond_sigma_zz``, ``bond_tau_xz`` and ``bond_weights`` at
``bond_x``. Every dataset has ``units`` and ``long_name``; coordinates are
HDF5 dimension scales attached to the fields (netCDF-4 readable). The body's
scalars (model, Poisson's ratio, scales, indicator maxima) are attributes.
"""

from __future__ import annotations

import h5py
import numpy as np

from .compute import BodyStresses

TAU_SIGN = (
    "tau_xz is the shear stress in this body's frame (x, z into the body): "
    "tau_xz(x, 0) = -p_t on body A, +p_t on body B"
)

#: dataset -> (long name, unit key, dimensions).
DATASETS = {
    "x": ("position along the rolling direction (global x)", "length", ("x",)),
    "z": ("depth below this body's surface (z >= 0, into the body)", "length", ("z",)),
    "sigma_xx": ("normal stress along x (compression negative)", "stress", ("z", "x")),
    "sigma_zz": ("normal stress along the depth z (compression negative)", "stress", ("z", "x")),
    "tau_xz": (
        "shear stress in this body's (x, z) frame; tau_xz(x, 0) = -p_t on body A, +p_t on body B",
        "stress",
        ("z", "x"),
    ),
    "sigma_yy": ("out-of-plane normal stress of plane strain, nu (sigma_xx + sigma_zz)", "stress", ("z", "x")),
    "von_mises": ("von Mises equivalent stress", "stress", ("z", "x")),
    "tresca": ("Tresca stress sigma_1 - sigma_3 (twice the maximum shear stress)", "stress", ("z", "x")),
    "sigma_1": ("largest principal stress", "stress", ("z", "x")),
    "sigma_2": ("middle principal stress", "stress", ("z", "x")),
    "sigma_3": ("smallest principal stress", "stress", ("z", "x")),
    "tau_xz_range": ("range of tau_xz over a rolling pass at each depth (max - min along x)", "stress", ("z",)),
    "surface_x": (
        "surface samples on z = 0: the contact nodes, the located contact edges and stick/slip boundaries",
        "length",
        ("surface_x",),
    ),
    "surface_sigma_xx": (
        "sigma_xx on the surface z = 0 at the surface samples (tension > 0)",
        "stress",
        ("surface_x",),
    ),
    "surface_sigma_zz": ("sigma_zz = p_n on the surface z = 0 at the surface samples", "stress", ("surface_x",)),
    "surface_tau_xz": (
        "tau_xz on the surface z = 0 at the surface samples (this body's frame)",
        "stress",
        ("surface_x",),
    ),
    "bond_x": ("bond-line node positions (the layer's bonded bottom)", "length", ("bond_x",)),
    "bond_sigma_zz": ("normal stress sigma_zz on the bond line (tension > 0)", "stress", ("bond_x",)),
    "bond_tau_xz": ("shear stress tau_xz on the bond line (this body's frame)", "stress", ("bond_x",)),
    "bond_weights": ("integration weight of each bond-line node (force = sum w sigma)", "length", ("bond_x",)),
}
COORDINATES = ("x", "z", "surface_x", "bond_x")


def write_bodies(group, bodies: dict[str, BodyStresses], units: dict[str, str] | None = None) -> None:
    """Fill the empty HDF5 ``group`` with one subgroup per body (``A``, ``B``); ``units`` maps "length",
    "stress" and "1" to unit names (default: each body's ``unit_length``/``unit_stress`` attributes)."""
    if units is None:
        first = next(iter(bodies.values())).attributes
        units = {"length": first.get("unit_length", "length"), "stress": first.get("unit_stress", "stress"), "1": "1"}
    group.attrs["long_name"] = "subsurface stresses of each requested body"
    group.attrs["convention"] = TAU_SIGN + "; compression negative"
    for label, stresses in bodies.items():
        sub = group.create_group(label)
        for key, value in stresses.attributes.items():
            sub.attrs[key] = value
        for name in (*COORDINATES, *(n for n in DATASETS if n not in COORDINATES)):
            if name not in stresses.arrays:
                continue
            long_name, unit, dims = DATASETS[name]
            ds = sub.create_dataset(name, data=np.asarray(stresses.arrays[name]))
            ds.attrs["units"] = units[unit]
            ds.attrs["long_name"] = long_name
            if name in COORDINATES:
                ds.make_scale(name)
            else:
                for axis, dim in enumerate(dims):
                    ds.dims[axis].attach_scale(sub[dim])


def read_stresses(group) -> dict[str, BodyStresses]:
    """The bodies of a ``stresses`` group written by :func:`write_bodies`."""
    out = {}
    for label, sub in group.items():
        arrays = {name: ds[()] for name, ds in sub.items() if isinstance(ds, h5py.Dataset)}
        attributes = {
            k: (v.decode() if isinstance(v, bytes) else v.item() if isinstance(v, np.generic) else v)
            for k, v in sub.attrs.items()
        }
        out[label] = BodyStresses(label, arrays, attributes)
    return out
