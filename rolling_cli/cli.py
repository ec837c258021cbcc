"""The ``rollc`` command line. The only place that catches errors and sets up logging.

Exit codes: 0 success; 1 the solve failed (no convergence, contact at the zone
edge, or a failed sweep case); 2 bad input (invalid case, gross sliding,
unreadable file).
"""

from __future__ import annotations

import logging
import os
import sys
import time
from pathlib import Path

import click

from . import __version__
from .errors import CaseError, GrossSlidingError, RollingError, SolveError

log = logging.getLogger("rolling_cli")


def _setup_logging(verbose: int, quiet: int) -> None:
    level = logging.WARNING + 10 * (quiet - verbose)
    logging.basicConfig(level=max(level, logging.DEBUG), format="%(levelname)s: %(message)s", stream=sys.stderr)
    logging.getLogger("rolling_cli").setLevel(max(level, logging.DEBUG))


def _fail(message: str, code: int) -> None:
    click.echo(f"error: {message}", err=True)
    sys.exit(code)


def _run(action):
    """Run a command body, mapping rolling_cli errors to one line and an exit code."""
    try:
        return action()
    except (CaseError, GrossSlidingError) as err:
        _fail(str(err), 2)
    except SolveError as err:
        _fail(str(err), 1)
    except RollingError as err:
        _fail(str(err), 1)
    except OSError as err:
        _fail(f"{err.filename or ''}: {err.strerror or err}", 2)


def default_output(case_path: str, configured: str | None) -> str:
    """Result path: ``[output] file`` if set, else the case file's name with .h5 in the working directory."""
    if configured:
        return configured
    return Path(case_path).with_suffix(".h5").name


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="rollc")
@click.option("-v", "--verbose", count=True, help="More log output (repeat for debug).")
@click.option("-q", "--quiet", count=True, help="Less output: warnings and errors only.")
@click.pass_context
def main(ctx: click.Context, verbose: int, quiet: int) -> None:
    """rollc: steady 2D rolling contact of elastic cylinders (BEM + generalised Newton)."""
    _setup_logging(verbose, quiet)
    ctx.obj = {"quiet": quiet > 0}


@main.command()
@click.argument("case_file", type=click.Path(dir_okay=False))
@click.option("-o", "--output", type=click.Path(dir_okay=False), help="Result file (.h5).")
@click.option("--keep-failed", is_flag=True, help="Write the last iterate of a failed solve, marked converged = false.")
@click.option("--plot", "make_plot", is_flag=True, help="Also write a PNG figure beside the result.")
@click.option("--no-cache", is_flag=True, help="Neither read nor write the on-disk BEM influence cache.")
@click.pass_context
def solve(ctx, case_file, output, keep_failed, make_plot, no_cache):
    """Solve CASE_FILE and write the result to HDF5."""

    def action():
        from .case import load_case
        from .io_hdf5 import write_result
        from .pipeline import solve as run_solve
        from .summary import summary

        case = load_case(case_file)
        out = output or default_output(case_file, case.output.file)
        start = time.perf_counter()
        result = run_solve(case, keep_failed=keep_failed, use_cache=not no_cache)
        result.attributes["time_total"] = time.perf_counter() - start
        write_result(result, out)
        if make_plot:
            from .plot import plot_file

            plot_file(out, os.path.splitext(out)[0] + ".png")
        if not ctx.obj["quiet"]:
            click.echo(summary(result, out))
        if not result.attributes.get("converged", True):
            _fail(f"{case_file}: {result.attributes.get('message')} (last iterate written to {out})", 1)

    _run(action)


@main.command()
@click.argument("case_file", type=click.Path(dir_okay=False))
def check(case_file):
    """Validate CASE_FILE and print the resolved case with the Hertz values it implies."""

    def action():
        from .case import case_to_toml, load_case
        from .pipeline import check_gross_sliding, plan

        case = load_case(case_file)
        check_gross_sliding(case)
        the_plan = plan(case)
        derived = {
            "derived": {
                "hertz_a": the_plan.half_width,
                "hertz_p0": the_plan.p0,
                "normal_load": the_plan.load,
                "effective_modulus": the_plan.modulus,
                "effective_radius": the_plan.radius,
                "beta_seed": the_plan.beta_seed,
                "beta_dundurs": 0.5 * the_plan.beta_seed,
                "contact_nodes": the_plan.grid.size,
                "node_spacing": the_plan.grid.spacing,
                "effects": the_plan.effects.line(),
            }
        }
        if case.normal.load is None:
            derived["derived"]["note"] = "hertz_a and normal_load are estimates from the overlap"
        click.echo(case_to_toml(case, derived), nl=False)

    _run(action)


if __name__ == "__main__":  # pragma: no cover
    main()
