"""Every kind of file rollc writes opens in netCDF-C (the ``netCDF4`` package, ``ncdump``) and in
xarray's default engine, and carries CF ``units`` and ``long_name`` on every variable (issue 25).

netCDF-C aborted (malloc errors, SIGABRT/SIGSEGV) on the fixed-length HDF5 strings the writer used to
store text in, so every netCDF-C read here runs in a subprocess: a crash fails the test, it cannot
kill pytest.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import h5py
import pytest

from helpers import case_dict, run_cli, write_case

pytest.importorskip("netCDF4", reason="netCDF4 (in the test extra) is the netCDF-C reader under test")

SMALL = case_dict(**{"discretization.contact_elements": 40})
STRESSES = {"points": [11, 7], "depth": 2.0}

#: Opens ``argv[1]`` with netCDF4 (every variable of every group read in full) and with xarray's
#: default engine; prints the groups as JSON.
READ = r"""
import json, sys
import netCDF4, xarray as xr
from xarray.backends.plugins import guess_engine

path = sys.argv[1]
groups = []

def walk(group, name):
    groups.append(name)
    for variable in group.variables.values():
        variable.set_auto_mask(False)
        variable[...]
    for child, sub in group.groups.items():
        walk(sub, f"{name}/{child}" if name else child)

with netCDF4.Dataset(path) as handle:
    walk(handle, "")
assert guess_engine(path) == "netcdf4", guess_engine(path)
# xarray's default engine: the root, the histories and one stresses group (the others have its
# layout), decoded and loaded; the h5netcdf engine is the other tests' reader
for group in [g for g in groups if g.count("/") == 0 or g.endswith("case_000000/A")]:
    with xr.open_dataset(path, group=group or None) as default:
        default.load()
print(json.dumps(groups))
"""


def _crash_free(command: list, what: str) -> subprocess.CompletedProcess:
    done = subprocess.run(command, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, f"{what}: exit {done.returncode} (negative: killed by signal)\n{done.stderr[-2000:]}"
    return done


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict:
    """One file of each kind: a single result, a two-key sweep, stresses (single and swept, one
    swept case failing: a text message), an adaptive result."""
    folder = tmp_path_factory.mktemp("netcdf")
    stresses = case_dict(SMALL, stresses=STRESSES)
    adaptive = case_dict(SMALL, **{"discretization.tolerance": 3e-3})
    runs = {
        "result": ("solve", write_case(folder, SMALL, "r.toml")),
        "sweep": ("sweep", write_case(folder, SMALL, "s.toml")),
        "stresses": ("solve", write_case(folder, stresses, "t.toml")),
        # the cases with one Newton iteration (from a cold start) fail in the run: text messages
        "stresses_sweep": (
            "sweep",
            write_case(folder, stresses, "u.toml"),
            *("--set", "tangential.q_over_mu_p=0.2,0.5", "--set", "solver.max_iterations=100,1"),
        ),
        "adaptive": ("solve", write_case(folder, adaptive, "a.toml")),
    }
    out = {}
    for name, (command, *args) in runs.items():
        path = folder / f"{name}.h5"
        # mu the fastest key: the third case of each load warm-starts (its variables: start_traction)
        keys = ("--set", "normal.load=900,1812.5", "--set", "friction.mu=0.1,0.2,0.3")
        extra = (*keys, "--workers", 1) if name == "sweep" else ("--workers", 1, "--no-warm-start")
        run = run_cli("-q", command, *args, *(extra if command == "sweep" else ()), "-o", path)
        assert run.exit_code in (0, 1), run.output  # 1: cases of the stresses sweep failed
        out[name] = path
    return out


KINDS = ("result", "sweep", "stresses", "stresses_sweep", "adaptive")


@pytest.mark.parametrize("kind", KINDS)
def test_netcdf_c_and_xarray_default_engine_read_every_group(files, kind):
    path = files[kind]
    done = _crash_free([sys.executable, "-c", READ, str(path)], f"netCDF4/xarray reading {kind}")
    groups = json.loads(done.stdout.splitlines()[-1])
    assert "" in groups and "convergence" in groups
    if kind.startswith("stresses"):
        assert "stresses/case_000000/A" in groups
    if shutil.which("ncdump"):
        header = _crash_free(["ncdump", "-h", str(path)], f"ncdump -h {kind}").stdout
        assert header.rstrip().endswith("}") and "string message(case)" in header


def _variables(path) -> dict[str, h5py.Dataset]:
    """Every variable of every group (a single result's soft links to its stresses group once)."""
    found = {}
    with h5py.File(path) as handle:

        def visit(name, obj):
            if isinstance(obj, h5py.Dataset):
                found[name] = {
                    "text": h5py.check_string_dtype(obj.dtype) is not None or obj.dtype.kind == "S",
                    **{k: obj.attrs[k] for k in ("units", "long_name", "flag_values") if k in obj.attrs},
                }

        handle.visititems(visit)  # visititems follows no soft links: each object once
    return found


@pytest.mark.parametrize("kind", KINDS)
def test_every_variable_has_long_name_and_units(files, kind):
    """CF: every variable a ``long_name``; every number ``units`` ("1" when dimensionless), except flag
    variables (``flag_values``, no units in CF) and text."""
    variables = _variables(files[kind])
    assert len(variables) > 60
    unnamed = sorted(name for name, attrs in variables.items() if not attrs.get("long_name"))
    unitless = sorted(
        name
        for name, attrs in variables.items()
        if not attrs["text"] and "flag_values" not in attrs and not attrs.get("units")
    )
    assert unnamed == [] and unitless == []


def test_swept_coordinates_carry_the_units_of_their_key(files):
    """friction.mu is dimensionless; normal.load a force per length, N/mm in the case's units."""
    variables = _variables(files["sweep"])
    assert variables["friction_mu"]["units"] == "1" and variables["normal_load_set"]["units"] == "N/mm"
    assert variables["normal_load_set"]["units"] == variables["normal_load"]["units"]
    assert "start_traction" in variables
    swept = _variables(files["stresses_sweep"])["tangential_q_over_mu_p"]
    assert swept["units"] == "1" and "q_over_mu_p" in swept["long_name"]


def test_text_reads_back_the_same_in_netcdf_c(files):
    """The failed case's message (and the converged case's empty one) through h5py and netCDF4."""
    path = str(files["stresses_sweep"])
    with h5py.File(path) as handle:
        messages = [m.decode() for m in handle["message"][()]]
    failed = [m for m in messages if m]
    assert len(failed) == 2 and all(m.startswith("sweep case (") and "solver.max_iterations = 1" in m for m in failed)
    assert messages.count("") == 2
    script = "import json, sys, netCDF4; print(json.dumps(list(netCDF4.Dataset(sys.argv[1])['message'][:])))"
    done = _crash_free([sys.executable, "-c", script, path], "netCDF4 reading the messages")
    assert json.loads(done.stdout) == messages


def test_a_file_with_fixed_length_text_is_read_and_resumed_into_one_netcdf_c_reads(tmp_path):
    """tests/data/v2_fixed_text.h5: a sweep (friction.mu = 0.1, 0.2, 0.3) that rollc 0.1's writer left
    after one case, its text fixed-length. rolling_cli reads it; ``--resume`` rewrites it: the two other
    cases added, text variable-length, the missing long_name/units added, and netCDF-C reads it."""
    from rolling_cli import read_result
    from rolling_cli.case import load_case
    from rolling_cli.study import sweep

    path = tmp_path / "old.h5"
    path.write_bytes((Path(__file__).parent / "data" / "v2_fixed_text.h5").read_bytes())
    with h5py.File(path) as handle:
        assert handle["title"].dtype.kind == "S" and handle.attrs["cases_complete"] == 1
    old = read_result(path, row=0)
    assert old.attributes["title"] == "format 2 fixed-text fixture" and old.attributes["message"] == ""
    base = load_case(case_dict(**{"discretization.contact_elements": 10, "title": "format 2 fixed-text fixture"}))
    report = sweep.run(base, sweep.spec_from_options(["friction.mu=0.1,0.2,0.3"], False), str(path), resume=True)
    assert sorted(report.records) == [1, 2] and report.skipped == 1
    _crash_free([sys.executable, "-c", READ, str(path)], "netCDF4/xarray reading the resumed file")
    variables = _variables(path)
    assert not [name for name, attrs in variables.items() if not attrs.get("long_name")]
    assert variables["friction_mu"]["units"] == "1"
    with h5py.File(path) as handle:
        assert list(handle["case"][()]) == [0, 1, 2] and h5py.check_string_dtype(handle["title"].dtype)
        assert [t.decode() for t in handle["title"][()]] == ["format 2 fixed-text fixture"] * 3
