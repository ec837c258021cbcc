"""Sweeps on a Dask cluster: the same file as the serial run, bit for bit."""

import pytest

from helpers import case_dict, run_cli, without_timings, write_case
from rolling_cli.case import load_case
from rolling_cli.study import sweep

pytest.importorskip("distributed")
xr = pytest.importorskip("xarray")

SMALL = case_dict(**{"discretization.contact_elements": 40})


def test_a_two_worker_local_cluster_writes_the_serial_file(tmp_path):
    case = write_case(tmp_path, SMALL)
    spec = sweep.spec_from_options(["friction.mu=0.05:0.5:20", "solver.max_iterations=100,1"], False)
    serial, cluster = tmp_path / "serial.h5", tmp_path / "cluster.h5"
    sweep.run(load_case(case), spec, str(serial), warm=False)
    report = sweep.run(load_case(case), spec, str(cluster), scheduler="local:2", warm=False)
    assert report.solved == 40 and int(report.failed_mask.sum()) == 20  # one Newton iteration, cold: recorded
    with xr.open_dataset(serial) as a, xr.open_dataset(cluster) as b:
        assert list(b.case.values) == list(range(40))  # streamed back in sweep order to the one writer
        a, b = (without_timings(d) for d in (a, b))
        for d in (a, b):
            d.attrs = {k: v for k, v in d.attrs.items() if k not in ("created", "history")}
        xr.testing.assert_identical(a, b)


def test_scheduler_errors_are_one_line(tmp_path):
    case = write_case(tmp_path, SMALL)
    both = run_cli("sweep", case, "--set", "friction.mu=0.1", "--workers", 2, "--scheduler", "local:2")
    assert both.exit_code == 2 and "choose one" in both.output
    bad = run_cli("sweep", case, "--set", "friction.mu=0.1", "--scheduler", "local:x", "-o", tmp_path / "s.h5")
    assert bad.exit_code == 2 and "allowed: local:N with N >= 1, or tcp://HOST:PORT" in bad.output
    assert not (tmp_path / "s.h5").exists()  # refused before the output was opened
