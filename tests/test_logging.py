"""rollc's verbosity: -v the solver's stages, strategies and timings; -vv its debug lines; third-party
loggers quiet unless asked (-vvv); the validity warning is part of the result (printed with -q, only
-qq hides it); -v/-q accepted after the subcommand too."""

import logging

import pytest

from helpers import STEEL, case_dict, run_cli, write_case
from rolling_cli import cli

SMALL = case_dict(**{"discretization.contact_elements": 40})
RUBBER = case_dict(
    **{
        "bodies.A": {"kind": "elastic", "radius": 100.0, "young": 10.0, "poisson": 0.49},
        "bodies.B": dict(STEEL),
        "discretization.contact_elements": 60,
    }
)
VALIDITY = "does not describe the cylinders"


@pytest.fixture(autouse=True)
def _restore_logging():
    """Each CLI run sets the levels; put the defaults back for the tests that follow."""
    yield
    logging.getLogger("rolling_cli").setLevel(logging.NOTSET)
    logging.getLogger().setLevel(logging.WARNING)


@pytest.mark.parametrize("where", ["before", "after"])
def test_verbose_shows_the_solver_stages_strategies_and_timings(tmp_path, where):
    case, out = write_case(tmp_path, SMALL), tmp_path / "r.h5"
    args = ["-v", "solve", case, "-o", out] if where == "before" else ["solve", case, "-o", out, "-v"]
    run = run_cli(*args)
    assert run.exit_code == 0, run.output
    assert "INFO: case grid: contact system of 120 nodes" in run.stderr  # 40 quadratic elements: 3 nodes each
    assert "INFO: case grid (cold start): " in run.stderr and " s, converged" in run.stderr
    assert "Newton iterations (direct" in run.stderr
    assert "DEBUG" not in run.stderr and "converged      yes" in run.stdout


def test_very_verbose_adds_debug_but_not_third_party_chatter(tmp_path):
    run = run_cli("solve", write_case(tmp_path, SMALL), "-o", tmp_path / "r.h5", "-vv")
    assert run.exit_code == 0, run.output
    assert "DEBUG: Newton strategy direct, stage tangential" in run.stderr
    assert all(line.startswith(("INFO: ", "DEBUG: ")) for line in run.stderr.splitlines())
    for name in ("h5py", "h5py._conv", "matplotlib", "distributed"):  # third-party debug: only with -vvv
        assert not logging.getLogger(name).isEnabledFor(logging.DEBUG)
    assert logging.getLogger("rolling_cli.solver.budget").isEnabledFor(logging.DEBUG)


def test_log_levels():
    W, I, D, E = logging.WARNING, logging.INFO, logging.DEBUG, logging.ERROR
    assert [cli.log_levels(v, 0) for v in range(4)] == [(W, W), (I, W), (D, W), (D, D)]
    assert [cli.log_levels(0, q) for q in range(3)] == [(W, W), (W, W), (E, E)]
    assert cli.log_levels(1, 1) == (W, W)  # -v and -q cancel


@pytest.mark.parametrize("args", [("-q", "solve"), ("solve", "-q")])
def test_quiet_still_prints_the_validity_warning(tmp_path, args):
    """a/R > 0.1: the result says the model does not apply; -q drops the summary, not that."""
    head, tail = (args, ()) if args[0] == "-q" else (("solve",), ("-q",))
    run = run_cli(*head, write_case(tmp_path, RUBBER), "-o", tmp_path / "r.h5", *tail)
    assert run.exit_code == 0, run.output
    assert run.stdout == ""
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("warning: ") and VALIDITY in lines[0] and "a/R = " in lines[0]


def test_very_quiet_silences_the_validity_warning(tmp_path):
    run = run_cli("solve", write_case(tmp_path, RUBBER), "-o", tmp_path / "r.h5", "-qq")
    assert run.exit_code == 0, run.output
    assert run.output == ""


def test_quiet_after_the_sweep_subcommand(tmp_path):
    out = tmp_path / "s.h5"
    run = run_cli("sweep", write_case(tmp_path, SMALL), "--set", "friction.mu=0.1,0.2", "-o", out, "-q")
    assert run.exit_code == 0, run.output
    assert run.output == "" and out.exists()


@pytest.mark.parametrize("quiet", [0, 1, 2])
def test_a_sweep_reports_the_validity_warning_of_its_cases(tmp_path, quiet):
    """Cases with a/R > 0.1 in a sweep: one warning line naming the first case and the count, with or
    without -q; -qq hides it."""
    flags = ["-q"] * quiet
    out = tmp_path / "s.h5"
    run = run_cli("sweep", write_case(tmp_path, RUBBER), "--set", "friction.mu=0.1,0.2", "-o", out, *flags)
    assert run.exit_code == 0, run.output
    warnings = [line for line in run.stderr.splitlines() if line.startswith("warning: ")]
    if quiet == 2:
        assert warnings == []
    else:
        assert len(warnings) == 1 and "sweep case (friction.mu = 0.1): " in warnings[0]
        assert VALIDITY in warnings[0] and "and 1 more cases" in warnings[0]
