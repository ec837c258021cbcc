"""The rollc command line: exit codes, one-line messages, output files."""

import math
import os

import h5py
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers import CARTER, case_dict, run_cli, write_case
from rolling_cli import __version__
from rolling_cli.pipeline import mesh_path

_write = write_case
_run = run_cli


def test_version():
    result = _run("--version")
    assert result.exit_code == 0 and __version__ in result.output


def test_solve_writes_result_and_summary(tmp_path):
    case = _write(tmp_path, CARTER)
    out = tmp_path / "out.h5"
    result = _run("solve", case, "-o", out)
    assert result.exit_code == 0, result.output
    for text in ("converged      yes", "Q/(mu P) = 0.51", "creepage", "adhesion", "slip", "time", "effects"):
        assert text in result.output
    with h5py.File(out) as f:
        assert f.attrs["format"] == "rolling_cli.result" and f["converged"][0]


def test_default_output_name_is_case_name_in_working_directory(tmp_path, monkeypatch):
    case = _write(tmp_path, CARTER, "mycase.toml")
    monkeypatch.chdir(tmp_path)
    assert _run("-q", "solve", case).exit_code == 0
    assert (tmp_path / "mycase.h5").exists()


def test_check_prints_resolved_case_with_hertz(tmp_path):
    result = _run("check", _write(tmp_path, CARTER))
    assert result.exit_code == 0
    assert "hertz_a = 1.0000" in result.output and "hertz_p0 = 1153.8" in result.output
    assert "max_iterations = 100" in result.output  # defaults are resolved


def test_bad_case_exits_2_with_one_line_and_no_traceback(tmp_path):
    case = _write(tmp_path, case_dict(**{"bodies.A.poisson": 0.7}))
    out = tmp_path / "out.h5"
    result = _run("solve", case, "-o", out)
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1
    assert "case.toml: bodies.A.poisson = 0.7: out of range; allowed: a number >= 0 and <= 0.5" in lines[0]
    assert "Traceback" not in result.output
    assert not out.exists()


def test_gross_sliding_exits_2(tmp_path):
    case = _write(tmp_path, case_dict(**{"tangential.q_over_mu_p": 1.0}))
    result = _run("solve", case, "-o", tmp_path / "o.h5")
    assert result.exit_code == 2 and "gross sliding" in result.output


def test_non_convergence_exits_1_and_writes_nothing_unless_asked(tmp_path):
    data = case_dict(**{"solver.max_iterations": 1, "bodies.A.young": 60260.0, "bodies.A.poisson": 0.31})
    case = _write(tmp_path, data)
    out = tmp_path / "o.h5"
    result = _run("solve", case, "-o", out)
    assert result.exit_code == 1
    assert "did not converge" in result.output and "relative residual" in result.output
    assert "likely cause" in result.output
    assert not out.exists() and not [p for p in os.listdir(tmp_path) if p.endswith(".tmp")]
    kept = _run("solve", case, "-o", out, "--keep-failed")
    assert kept.exit_code == 1
    with h5py.File(out) as f:
        assert not f["converged"][0] and "did not converge" in f["message"][0].decode()
        assert len(f["convergence/residual"]) >= 1


def test_zone_too_small_is_enlarged_and_says_so(tmp_path):
    case = _write(tmp_path, case_dict(**{"discretization.zone": 1.001, "discretization.contact_elements": 50}))
    out = tmp_path / "o.h5"
    result = _run("solve", case, "-o", out)
    assert result.exit_code == 0, result.output
    assert "NOTE           discretization.zone enlarged from 1.001 to 1.5015" in result.output
    with h5py.File(out) as f:
        assert "enlarged" in f["zone_note"][0].decode()
        import tomllib

        used = tomllib.loads(f.attrs["case"])["discretization"]["zone"]
        assert used == pytest.approx(1.5015)  # the file records the zone actually used


def test_zone_limit_fails_clearly(tmp_path, monkeypatch):

    monkeypatch.setattr(mesh_path, "ZONE_LIMIT", 1.2)
    case = _write(tmp_path, case_dict(**{"discretization.zone": 1.001, "discretization.contact_elements": 50}))
    result = _run("solve", case, "-o", tmp_path / "o.h5")
    assert result.exit_code == 1
    assert "edge of the potential contact zone" in result.output and "discretization.zone" in result.output


_KEYS = [
    ("bodies.A.young", st.one_of(st.floats(max_value=0.0, allow_nan=False), st.text(max_size=5), st.booleans())),
    ("bodies.B.poisson", st.one_of(st.floats(min_value=0.5000001, max_value=1e6), st.floats(max_value=-1e-9))),
    ("friction.mu", st.one_of(st.floats(max_value=-1e-12), st.just(math.nan), st.text(max_size=3))),
    ("rolling.direction", st.integers().filter(lambda v: v not in (-1, 1))),
    ("discretization.contact_elements", st.one_of(st.integers(max_value=1), st.floats(allow_nan=False))),
    ("discretization.influence", st.text(max_size=8).filter(lambda v: v not in ("bem", "half-plane"))),
    ("solver.tolerance", st.one_of(st.floats(max_value=0.0, allow_nan=False), st.floats(min_value=1.0))),
    ("normal.load", st.floats(max_value=0.0, allow_nan=False)),
]


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(choice=st.sampled_from(range(len(_KEYS))), data=st.data())
def test_broken_cases_exit_2_naming_the_key(tmp_path, choice, data):
    key, strategy = _KEYS[choice]
    value = data.draw(strategy)
    if isinstance(value, float) and math.isnan(value):
        value = "nan"  # TOML text for NaN is written by tomli-w as nan
    case = _write(tmp_path, case_dict(**{key: value}))
    result = _run("solve", case, "-o", tmp_path / "o.h5")
    assert result.exit_code == 2, result.output
    line = result.output.strip()
    assert "\n" not in line and "Traceback" not in line
    assert "case.toml" in line and key in line and "allowed" in line


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(key=st.text(alphabet="abcdefghijklmnopqrstuvwxyz_", min_size=1, max_size=10))
def test_unknown_keys_exit_2(tmp_path, key):
    """A key that [friction] does not have is refused by name; the schema's own keys (``law``,
    ``mu_static``, ...: valid keys with other types or rules) are not unknown, so they are not drawn."""
    import dataclasses

    from rolling_cli.case.schema import Friction

    if key in CARTER["friction"] or key in {f.name for f in dataclasses.fields(Friction)}:
        return
    case = _write(tmp_path, case_dict(**{f"friction.{key}": 1.0}))
    result = _run("check", case)
    assert result.exit_code == 2
    assert f"friction.{key} = 1.0: unknown key" in result.output


def test_plain_garbage_file_exits_2(tmp_path):
    path = tmp_path / "case.toml"
    path.write_bytes(np.random.default_rng(0).bytes(200))
    result = _run("solve", path)
    assert result.exit_code == 2 and "case.toml" in result.output


def test_error_estimate_is_reported_and_stored(tmp_path):
    """--error-estimate re-solves on half the elements: the difference is an upper bound on
    the traction error here (benchmarks/results/accuracy_cost.md: 2.5-5.6x for Carter)."""
    out = tmp_path / "e.h5"
    result = _run(
        "solve", _write(tmp_path, case_dict(**{"discretization.contact_elements": 80})), "-o", out, "--error-estimate"
    )
    assert result.exit_code == 0, result.output
    assert "error estimate against 40 elements" in result.output
    with h5py.File(out) as f:
        estimate = f["error_estimate"][0]
        x, p_t = f["x"][()], f["p_t"][0]
        a, p0, mu = f["hertz_a"][0], f["hertz_p0"][0], f["mu"][0]
        assert f["error_estimate_elements"][0] == 40
        assert 0 < f["error_estimate_rms"][0] < estimate
    from rolling_cli.references import carter

    true_error = np.max(np.abs(p_t - carter.traction(x, 0.51, a, p0, mu, -1))) / (mu * p0)
    assert true_error <= estimate


def test_an_existing_output_is_never_replaced_silently(tmp_path):
    case = _write(tmp_path, case_dict(**{"discretization.contact_elements": 40}))
    out = tmp_path / "o.h5"
    assert _run("-q", "solve", case, "-o", out).exit_code == 0
    before = out.read_bytes()
    again = _run("-q", "solve", case, "-o", out)
    assert again.exit_code == 2
    assert again.output.strip() == f"error: {out}: exists; allowed: --overwrite, or another output name"
    assert out.read_bytes() == before
    assert _run("-q", "solve", case, "-o", out, "--overwrite").exit_code == 0
    stranger = tmp_path / "notes.txt"
    stranger.write_text("mine")
    refused = _run("-q", "solve", case, "-o", stranger)
    assert refused.exit_code == 2 and stranger.read_text() == "mine"


@pytest.mark.parametrize("target", ["case", "link", "device"])
def test_outputs_that_are_inputs_links_or_devices_are_refused_even_with_overwrite(tmp_path, target):
    case = _write(tmp_path, case_dict(**{"discretization.contact_elements": 40}), "victim.toml")
    text = case.read_text()
    if target == "case":
        out = case
    elif target == "link":
        out = tmp_path / "link.h5"
        out.symlink_to(tmp_path / "elsewhere.h5")
    else:
        out = "/dev/null"
    result = _run("-q", "solve", case, "-o", out, "--overwrite")
    assert result.exit_code == 2, result.output
    line = result.output.strip()
    assert "\n" not in line and "allowed" in line
    assert {"case": "an input of this command", "link": "a symbolic link", "device": "not a regular file"}[
        target
    ] in line
    assert case.read_text() == text and not (tmp_path / "elsewhere.h5").exists()


def test_a_case_named_h5_keeps_its_input(tmp_path, monkeypatch):
    """A case file called study.h5, solved with the default output (the case name with .h5), is not overwritten."""
    case = _write(tmp_path, case_dict(**{"discretization.contact_elements": 40}), "study.h5")
    monkeypatch.chdir(tmp_path)
    text = case.read_text()
    result = _run("-q", "solve", "study.h5", "--overwrite")
    assert result.exit_code == 2 and "an input of this command" in result.output
    assert case.read_text() == text


@pytest.mark.parametrize("configured", ["/tmp/elsewhere.h5", "../up.h5", "sub/../../up.h5"])
def test_output_file_of_a_case_stays_in_the_working_directory(tmp_path, monkeypatch, configured):
    case = _write(tmp_path, case_dict(**{"discretization.contact_elements": 40, "output.file": configured}))
    monkeypatch.chdir(tmp_path)
    result = _run("-q", "solve", case)
    assert result.exit_code == 2
    assert f"case.toml: output.file = '{configured}': leaves the working directory" in result.output
    given = _run("-q", "solve", case, "-o", tmp_path / "chosen.h5")  # the command line may name any path
    assert given.exit_code == 0 and (tmp_path / "chosen.h5").exists()


def test_the_plot_never_takes_the_results_path(tmp_path):
    case = _write(tmp_path, case_dict(**{"discretization.contact_elements": 40}))
    out = tmp_path / "x.png"
    assert _run("-q", "solve", case, "-o", out, "--plot").exit_code == 0
    with h5py.File(out) as f:  # the result kept its name ...
        assert f.attrs["format"] == "rolling_cli.result"
    assert (tmp_path / "x.png.png").read_bytes()[:4] == b"\x89PNG"  # ... and the figure went beside it
    existing = tmp_path / "r.png"
    existing.write_bytes(b"a figure of mine")
    refused = _run("-q", "solve", case, "-o", tmp_path / "r.h5", "--plot")
    assert refused.exit_code == 2 and f"{existing}: exists" in refused.output
    assert not (tmp_path / "r.h5").exists()  # checked before anything was solved or written


@pytest.mark.parametrize("command", ["solve", "sweep"])
def test_a_second_writer_of_one_output_is_refused_at_once(tmp_path, command):
    """Two processes: one holds the output's lock (as a running rollc does); the other stops at once."""
    import subprocess
    import sys
    import time

    out = tmp_path / "o.h5"
    holder = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import sys, time; from rolling_cli.files import outputs\n"
            f"with outputs.claim({str(out)!r}):\n    print('locked', flush=True); time.sleep(60)",
        ],
        stdout=subprocess.PIPE,
    )
    try:
        assert holder.stdout.readline().strip() == b"locked"
        case = _write(tmp_path, case_dict(**{"discretization.contact_elements": 40}))
        extra = ["--set", "friction.mu=0.1,0.2"] if command == "sweep" else []
        start = time.perf_counter()
        result = _run("-q", command, case, *extra, "-o", out)
        assert result.exit_code == 2
        assert f"{out}: another rollc process (pid {holder.pid}) is writing it" in result.output
        assert time.perf_counter() - start < 30 and not out.exists()
    finally:
        holder.kill()
        holder.communicate()
    assert _run("-q", command, case, *extra, "-o", out).exit_code == 0  # a killed holder released the lock
