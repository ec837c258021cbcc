"""rollc sweep: parameter studies, reuse, parallel equality, resume, failures, interruption."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

from helpers import CARTER, case_dict, run_cli, write_case
from rolling_cli import sweep
from rolling_cli.case import load_case
from rolling_cli.errors import CaseError

CASES = Path(__file__).resolve().parents[1] / "cases"
SMALL = case_dict(**{"discretization.contact_elements": 40})


_write = write_case
_run = run_cli


def _arrays(path):
    with h5py.File(path) as f:
        return {
            name: {k: f["cases"][name][k][()] for k in ("p_n", "p_t", "s_t", "state")}
            for name in sorted(f["cases"])
            if "p_t" in f["cases"][name]
        }


def test_friction_sweep_writes_one_group_per_value(tmp_path):
    out = tmp_path / "s.h5"
    result = _run("sweep", _write(tmp_path, SMALL), "--set", "friction.mu=0.1,0.2,0.3,0.4", "-o", out, "--workers", 1)
    assert result.exit_code == 0, result.output
    assert "friction.mu  converged" in result.output  # the summary table
    with h5py.File(out) as f:
        assert f.attrs["format"] == "rolling_cli.sweep"
        assert sorted(f["cases"]) == ["0000", "0001", "0002", "0003"]
        mus = [f["cases"][n].attrs["friction.mu"] for n in sorted(f["cases"])]
        assert mus == [0.1, 0.2, 0.3, 0.4]
        for name in f["cases"]:
            group = f["cases"][name]
            assert group.attrs["format"] == "rolling_cli.result" and group.attrs["converged"]
            assert group.attrs["mu"] == group.attrs["friction.mu"]
            assert "p_t" in group and "convergence" in group
        summary = f["summary"]
        assert list(summary["friction.mu"][()]) == mus
        for column in ("converged", "q_over_mu_p", "creep", "normal_load", "tangential_load", "iterations", "time"):
            assert summary[column].shape == (4,)
        assert np.allclose(summary["q_over_mu_p"][()], 0.51, rtol=1e-9)


def test_values_ranges_product_and_zip():
    spec = sweep.spec_from_options(["friction.mu=0.1:0.4:4", "tangential.q_over_mu_p=0.2,0.5"], zipped=False)
    assert spec.values[0] == pytest.approx((0.1, 0.2, 0.3, 0.4))
    assert len(spec.combinations()) == 8
    zipped = sweep.spec_from_options(["friction.mu=0.1,0.2", "tangential.q_over_mu_p=0.2,0.5"], zipped=True)
    assert zipped.combinations() == [
        {"friction.mu": 0.1, "tangential.q_over_mu_p": 0.2},
        {"friction.mu": 0.2, "tangential.q_over_mu_p": 0.5},
    ]
    assert sweep.spec_from_options(["discretization.contact_elements=10:40:4"], False).values[0] == (10, 20, 30, 40)
    with pytest.raises(CaseError, match="unknown case key"):
        sweep.spec_from_options(["friction.muu=0.1"], False)
    with pytest.raises(CaseError, match="friction.mu = -0.1: out of range"):
        sweep.spec_from_options(["friction.mu=-0.1,0.2"], False)


def test_every_case_is_validated_before_the_first_solve(tmp_path):
    out = tmp_path / "s.h5"
    case = _write(tmp_path, SMALL)
    result = _run("sweep", case, "--set", "bodies.A.poisson=0.3,0.7", "-o", out)
    assert result.exit_code == 2
    assert "bodies.A.poisson = 0.7: out of range" in result.output
    assert not out.exists()


def test_workers_give_the_serial_result_exactly(tmp_path):
    case = _write(tmp_path, SMALL)
    serial, parallel = tmp_path / "serial.h5", tmp_path / "parallel.h5"
    values = "friction.mu=0.05:0.5:12"  # 12 cases: two chunks, so both workers work
    assert _run("-q", "sweep", case, "--set", values, "-o", serial, "--workers", 1).exit_code == 0
    assert _run("-q", "sweep", case, "--set", values, "-o", parallel, "--workers", 2).exit_code == 0
    a, b = _arrays(serial), _arrays(parallel)
    assert a.keys() == b.keys() and len(a) == 12
    for name in a:
        for key in a[name]:
            assert np.array_equal(a[name][key], b[name][key]), (name, key)


def test_resume_solves_nothing_twice(tmp_path):
    base = load_case(SMALL)
    spec = sweep.spec_from_options(["friction.mu=0.1,0.2,0.3,0.4"], False)
    out = str(tmp_path / "s.h5")
    first = sweep.run(base, spec, out)
    assert len(first.records) == 4
    again = sweep.run(base, spec, out, resume=True)
    assert len(again.records) == 0 and again.skipped == 4
    with h5py.File(out, "a") as f:  # lose two cases, as an interrupted run would
        del f["cases/0001"], f["cases/0003"]
    rest = sweep.run(base, spec, out, resume=True)
    assert sorted(rest.records) == [1, 3] and rest.skipped == 2
    with h5py.File(out) as f:
        assert sorted(f["cases"]) == ["0000", "0001", "0002", "0003"]
        assert list(f["summary/index"][()]) == [0, 1, 2, 3]
    other = sweep.spec_from_options(["friction.mu=0.5,0.6,0.7,0.8"], False)
    with pytest.raises(CaseError, match="other swept values"):
        sweep.run(base, other, out, resume=True)


def test_failing_case_is_recorded_and_the_others_finish(tmp_path):
    out = tmp_path / "s.h5"
    case = _write(tmp_path, SMALL)
    result = _run("sweep", case, "--set", "tangential.q_over_mu_p=0.3,1.2,0.8", "-o", out, "--workers", 1)
    assert result.exit_code == 1
    assert "1 of 3 cases failed" in result.output
    with h5py.File(out) as f:
        assert list(f["summary/converged"][()]) == [True, False, True]
        failed = f["cases/0001"]
        assert not failed.attrs["converged"] and "gross sliding" in failed.attrs["message"]
        assert "gross sliding" in f["summary/message"][1].decode()
        assert f["cases/0002"].attrs["converged"]


def test_an_interrupted_sweep_leaves_a_valid_file(tmp_path):
    """Ctrl-C (KeyboardInterrupt) after two cases: the file holds exactly those two."""
    base = load_case(SMALL)
    spec = sweep.spec_from_options(["friction.mu=0.1:0.9:9"], False)
    out = str(tmp_path / "s.h5")

    def stop_after_two(done, total, failed):
        if done == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        sweep.run(base, spec, out, progress=stop_after_two)
    with h5py.File(out) as f:
        assert sorted(f["cases"]) == ["0000", "0001"]
        assert list(f["summary/index"][()]) == [0, 1]
    rest = sweep.run(base, spec, out, resume=True)
    assert len(rest.records) == 7


def test_a_killed_sweep_leaves_a_valid_file(tmp_path):
    """SIGTERM to the running command: exit 130, a readable file with the finished cases."""
    case = _write(tmp_path, SMALL)
    out = tmp_path / "s.h5"
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "rolling_cli",
            "-q",
            "sweep",
            str(case),
            "--set",
            "friction.mu=0.01:1:3000",
            "-o",
            str(out),
            "--workers",
            "1",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env={**os.environ, "PYTHONWARNINGS": "ignore"},
    )
    deadline = time.time() + 60
    while time.time() < deadline:
        time.sleep(0.5)
        try:
            with h5py.File(out) as f:
                if len(f["cases"]) >= 1:
                    break
        except (OSError, KeyError):
            continue
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert b"continue with --resume" in err
    with h5py.File(out) as f:
        n = len(f["cases"])
        assert 1 <= n < 3000
        assert len(f["summary/index"]) == n
        assert all(f["cases"][name].attrs["converged"] for name in f["cases"])
    assert not [p for p in os.listdir(tmp_path) if p.endswith(".tmp")]


def test_case_file_sweep_table_and_creep_force_curve(tmp_path):
    data = case_dict(SMALL, **{"tangential.q_over_p": 0.051})
    data["sweep"] = {"friction.mu": [0.1, 0.2, 0.3, 0.4]}  # the paper's Fig. 4
    out = tmp_path / "fig4.h5"
    assert _run("-q", "sweep", _write(tmp_path, data), "-o", out, "--workers", 1).exit_code == 0
    with h5py.File(out) as f:
        assert len(f["cases"]) == 4
        stick = [np.sum(f["cases"][n]["state"][()] == 1) for n in sorted(f["cases"])]
        assert stick == sorted(stick)  # the adhesion zone grows with friction (paper, Fig. 4)
    curve = tmp_path / "curve.h5"
    assert _run("-q", "sweep", _write(tmp_path, SMALL), "--curve", "load", "--points", 9, "-o", curve).exit_code == 0
    with h5py.File(curve) as f:
        q = f["summary/q_over_mu_p"][()]
        creep = f["summary/creep"][()]
    assert q[0] == pytest.approx(-0.99) and q[-1] == pytest.approx(0.99)
    assert np.all(np.diff(creep) < 0)  # Q falls as the creepage rises: a monotone creep-force curve


def test_no_sweep_given_is_a_bad_input(tmp_path):
    result = _run("sweep", _write(tmp_path, CARTER))
    assert result.exit_code == 2 and "no sweep given" in result.output
