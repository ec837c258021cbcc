"""The ``rollc`` command line. The only place that catches errors and sets up logging.

Exit codes: 0 success; 1 the solve failed (no convergence, contact at the zone
edge, or a failed sweep case) or an output could not be written; 2 bad input
(invalid case, gross sliding, unreadable file, an output path refused or in
use by another rollc); 130 interrupted (Ctrl-C, SIGTERM).
"""

from __future__ import annotations

import gc
import logging
import os
import shlex
import signal
import sys
import time
from pathlib import Path

import click

from . import process
from ._version import __version__
from .errors import CaseError, GrossSlidingError, RollingError, SolveError
from .terminal import Progress, log_levels, setup_logging, verbosity_options  # noqa: F401 (log_levels: the CLI's public name)

log = logging.getLogger("rolling_cli")


def _fail(message: str, code: int) -> None:
    click.echo(f"error: {message}", err=True)
    sys.exit(code)


def _run(action):
    """Run a command body, mapping rolling_cli errors to one line and an exit code."""
    from .files.outputs import WriteError

    try:
        return action()
    except (CaseError, GrossSlidingError) as err:
        _fail(str(err), 2)
    except WriteError as err:
        if err.fatal:  # HDF5 cannot release a file whose write failed; its exit handler would crash
            click.echo(f"error: {err}", err=True)
            sys.stdout.flush()
            sys.stderr.flush()
            os._exit(1)
        _fail(str(err), 1)
    except SolveError as err:
        _fail(str(err), 1)
    except RollingError as err:
        _fail(str(err), 1)
    except OSError as err:
        _fail(f"{err.filename or ''}: {err.strerror or err}", 2)


def _imported() -> None:
    """A command's modules are imported: garbage collection on again, if :func:`entry` turned it off
    for the start-up, with the objects of the imports moved out of its reach first (``gc.freeze``:
    modules, functions and classes live to the end anyway; otherwise the first collection would
    traverse them all)."""
    if not gc.isenabled():
        gc.freeze()
        gc.enable()


def _command() -> str:
    """This command (its arguments and the options given), for the ``history`` attribute of its files."""
    ctx = click.get_current_context()
    parts = ["rollc", ctx.info_name]
    for param in ctx.command.params:
        value = ctx.params.get(param.name)
        if isinstance(param, click.Argument):
            parts.append(str(value))
        elif value not in (None, False, (), param.default):
            values = value if isinstance(value, tuple) else (value,)
            for item in values:
                parts += [param.opts[-1]] if item is True else [param.opts[-1], str(item)]
    return shlex.join(str(part) for part in parts)


def default_output(case_path: str, configured: str | None) -> str:
    """Result path: ``[output] file`` if set (relative, inside the working directory), else the
    case file's name with .h5 in the working directory."""
    if configured:
        from .files.outputs import confined_output

        return confined_output(configured, case_path)
    return Path(case_path).with_suffix(".h5").name


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="rollc")
@click.option("-v", "--verbose", count=True, help="The solver's stages, strategies and timings; -vv: debug too.")
@click.option(
    "-q", "--quiet", count=True, help="No summary: warnings (validity of the result too) and errors; -qq: errors only."
)
@click.pass_context
def main(ctx: click.Context, verbose: int, quiet: int) -> None:
    """rollc: steady 2D rolling contact of elastic cylinders (BEM + generalised Newton)."""
    setup_logging(verbose, quiet)
    ctx.obj = {"quiet": quiet > 0, "v": verbose, "q": quiet}


@main.command()
@verbosity_options
@click.argument("case_file", type=click.Path(dir_okay=False))
@click.option("-o", "--output", type=click.Path(dir_okay=False), help="Result file (.h5).")
@click.option("--overwrite", is_flag=True, help="Replace an existing output file (and figure).")
@click.option("--keep-failed", is_flag=True, help="Write the last iterate of a failed solve, marked converged = false.")
@click.option("--plot", "make_plot", is_flag=True, help="Also write a PNG figure beside the result.")
@click.option("--no-cache", is_flag=True, help="Neither read nor write the on-disk BEM influence cache.")
@click.option("--error-estimate", is_flag=True, help="Re-solve on half the contact elements and report the difference.")
@click.pass_context
def solve(ctx, case_file, output, overwrite, keep_failed, make_plot, no_cache, error_estimate):
    """Solve CASE_FILE and write the result to HDF5."""

    def action():
        from . import blas
        from .case import load_case
        from .files import outputs
        from .files.io_hdf5 import write_result
        from .pipeline import solve as run_solve

        _imported()
        case = load_case(case_file)
        out = output or default_output(case_file, case.output.file)
        outputs.check_output(out, inputs=(case_file,), overwrite=overwrite)
        figure = outputs.figure_path(out) if make_plot else None
        if figure:
            outputs.check_output(figure, inputs=(case_file, out), overwrite=overwrite, kind="figure")
        signal.signal(signal.SIGTERM, _terminate)
        with outputs.claim(out), blas.command_threads():
            start = time.perf_counter()
            result = run_solve(case, keep_failed=keep_failed, use_cache=not no_cache)
            if error_estimate and result.attributes.get("converged"):
                from .pipeline.estimate import add_error_estimate

                add_error_estimate(case, result, use_cache=not no_cache)
            result.attributes["time_total"] = time.perf_counter() - start
            write_result(result, out, overwrite=overwrite, command=_command())
            if figure:
                from .report.plot import plot_file

                plot_file(out, figure)
        if not ctx.obj["quiet"]:
            from .report.summary import summary

            click.echo(summary(result, out))
        elif ctx.obj["q"] < 2 and result.attributes.get("validity_warning"):  # part of the result: only -qq hides it
            click.echo(f"warning: {result.attributes['validity_warning']}", err=True)
        if not result.attributes.get("converged", True):
            _fail(f"{case_file}: {result.attributes.get('message')} (last iterate written to {out})", 1)

    try:
        _run(action)
    except KeyboardInterrupt:
        _fail("interrupted: nothing was written", 130)


@main.command()
@verbosity_options
@click.argument("case_file", type=click.Path(dir_okay=False))
def check(case_file):
    """Validate CASE_FILE and print the resolved case with the Hertz values it implies."""

    def action():
        from .case import case_to_toml, load_case
        from .pipeline import check_gross_sliding, plan
        from .pipeline.resources import check_resources

        _imported()
        case = load_case(case_file)
        check_gross_sliding(case)
        needs = check_resources(case)
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
                **needs.as_dict(),
            }
        }
        if case.normal.load is None:
            derived["derived"]["note"] = "hertz_a and normal_load are estimates from the overlap"
        click.echo(case_to_toml(case, derived), nl=False)

    _run(action)


@main.command()
@verbosity_options
@click.argument("result_file", type=click.Path(dir_okay=False))
@click.option("-o", "--output", type=click.Path(dir_okay=False), help="Figure file: .png, .pdf or .svg.")
@click.option("--show", is_flag=True, help="Open the figure in a window.")
@click.option(
    "--stresses", is_flag=True, help="Contour maps of the subsurface stresses (default output: NAME_stresses.png)."
)
@click.option(
    "--deformed", is_flag=True, help="The deformed contact region to scale (default output: NAME_deformed.png)."
)
@click.option("--magnify", type=float, default=1.0, show_default=True, help="--deformed: displacements times K.")
@click.option("--overwrite", is_flag=True, help="Replace an existing figure file.")
def plot(result_file, output, show, stresses, deformed, magnify, overwrite):
    """Plot a result or sweep file (default output: the file's name with .png)."""

    def action():
        from .files import outputs
        from .report.plot import FORMATS, plot_file

        _imported()
        draw, stem = plot_file, os.path.splitext(result_file)[0]
        if magnify != 1.0 and not deformed:
            raise CaseError(f"--magnify {magnify}: allowed only with --deformed")
        if stresses:
            from .report.plot_stresses import plot_stress_file as draw

            stem += "_stresses"
        elif deformed:
            from functools import partial

            from .report.plot_deformed import plot_deformed_file

            draw, stem = partial(plot_deformed_file, magnify=magnify), stem + "_deformed"
        if not os.path.exists(result_file):
            raise CaseError("file not found; allowed: a result or sweep file written by rollc", file=result_file)
        out = output or (None if show else outputs.figure_path(stem + ".h5" if stresses or deformed else result_file))
        if out and os.path.splitext(out)[1].lower() not in FORMATS:
            raise CaseError(f"-o {out}: unsupported figure format; allowed: {', '.join(FORMATS)}")
        if out:
            outputs.check_output(out, inputs=(result_file,), overwrite=overwrite, kind="figure")
        try:
            draw(result_file, out, show)
        except (OSError, KeyError, ValueError, IndexError) as err:
            raise CaseError(f"not a readable rolling_cli result or sweep file ({err})", file=result_file) from None
        if out:
            click.echo(f"written {out}")

    _run(action)


@main.command()
@verbosity_options
@click.argument("result_file", type=click.Path(dir_okay=False))
@click.option("-o", "--output", type=click.Path(dir_okay=False), help="Table file [default: FILE with .csv].")
@click.option("--fields", is_flag=True, help="Also write the per-node fields to *_fields.csv.")
@click.option("--overwrite", is_flag=True, help="Replace existing table files.")
def export(result_file, output, fields, overwrite):
    """Write the summary table of a result or sweep file (one row per case) as CSV."""

    def action():
        from .files import outputs
        from .files.export import export as write_tables
        from .files.export import fields_path

        _imported()
        if not os.path.exists(result_file):
            raise CaseError("file not found; allowed: a result or sweep file written by rollc", file=result_file)
        out = output or os.path.splitext(result_file)[0] + ".csv"
        targets = [out] + ([fields_path(out)] if fields else [])
        for target in targets:
            outputs.check_output(target, inputs=(result_file,), overwrite=overwrite, kind="table")
        try:
            written = write_tables(result_file, out, fields=fields, overwrite=overwrite)
        except (KeyError, ValueError, IndexError) as err:
            raise CaseError(f"not a readable rolling_cli result or sweep file ({err})", file=result_file) from None
        except OSError as err:
            if isinstance(err, FileNotFoundError) or err.errno is None:
                raise CaseError(f"not a readable rolling_cli result or sweep file ({err})", file=result_file) from None
            raise
        for path in written:
            click.echo(f"written {path}")

    _run(action)


def _span(text: str, option: str = "--range", what: str = "xi R*/(mu a)") -> tuple[float, float]:
    """LO:HI of ``--range`` (or ``option``); CaseError naming the option otherwise."""
    try:
        lo, hi = (float(part) for part in text.split(":"))
    except ValueError:
        raise CaseError(f"{option} = {text!r}: allowed: LO:HI, two numbers ({what})") from None
    return lo, hi


@main.command()
@verbosity_options
@click.argument("case_file", type=click.Path(dir_okay=False))
@click.option("-o", "--output", type=click.Path(dir_okay=False), help="Table file (.h5) [default: CASE_table.h5].")
@click.option(
    "--tolerance", type=float, default=1e-3, show_default=True, help="Largest interpolation error, in Q/(mu P)."
)
@click.option(
    "--range", "span", default="-1:1", show_default=True, help="LO:HI of the creepage normalised as xi R*/(mu a)."
)
@click.option("--mu", "friction", default=None, help="LO:HI: a second axis, the coefficient of friction.")
@click.option(
    "--workers", type=click.IntRange(1, 256), default=1, show_default=True, help="Worker processes (rows of --mu)."
)
@click.option("--scheduler", default=None, help="Rows of --mu on a Dask cluster: tcp://HOST:PORT or local:N.")
@click.option("--resume", is_flag=True, help="Take the rows of --mu an interrupted run finished (TABLE.rows).")
@click.option("--overwrite", is_flag=True, help="Replace an existing table file.")
@click.option("--no-cache", is_flag=True, help="Neither read nor write the on-disk BEM influence cache.")
@click.pass_context
def table(ctx, case_file, output, tolerance, span, friction, workers, scheduler, resume, overwrite, no_cache):
    """Tabulate Q/(mu P) against xi R*/(mu a) for CASE_FILE, sampled adaptively (rolling_cli.table.load reads it)."""

    def action():
        from . import table as table_file
        from .case import load_case
        from .files import outputs
        from .study.tabulate import build, build_friction, check_request

        _imported()
        lo, hi = _span(span)
        mu_range = _span(friction, "--mu", "mu") if friction is not None else None
        if scheduler and (workers > 1 or mu_range is None):
            raise CaseError(
                f"--scheduler {scheduler} with {'--workers' if workers > 1 else 'one axis'}; allowed: --scheduler "
                "with --mu (its rows are the tasks) and without --workers"
            )
        case = load_case(case_file)
        check_request(case, lo, hi, tolerance, case_file)
        if mu_range is not None and not 0.0 < mu_range[0] < mu_range[1]:
            raise CaseError(f"--mu = {friction}: allowed: LO:HI with 0 < LO < HI", file=case_file)
        out = output or Path(case_file).stem + "_table.h5"
        outputs.check_output(out, inputs=(case_file,), overwrite=overwrite, kind="table")
        with outputs.claim(out):
            if mu_range is None:
                made, intervals = build(case, lo, hi, tolerance, use_cache=not no_cache)
                shape = f"{made.nodes.size} nodes"
                with outputs.atomic_file(out, replace=overwrite) as tmp:
                    table_file.write(tmp, made, intervals)
            else:
                from .study.table_rows import open_journal
                from .study.tabulate import INITIAL

                journal = open_journal(out, case, (lo, hi), mu_range, tolerance, INITIAL, resume, overwrite)
                try:
                    made, errors = build_friction(
                        case,
                        lo,
                        hi,
                        *mu_range,
                        tolerance,
                        use_cache=not no_cache,
                        workers=workers,
                        journal=journal,
                        scheduler=scheduler,
                    )
                    shape = f"{len(made.rows)} rows of mu = {mu_range[0]:g} .. {mu_range[1]:g}, each"
                    with outputs.atomic_file(out, replace=overwrite) as tmp:
                        table_file.write_friction(tmp, made, errors)
                except KeyboardInterrupt:
                    journal.close()
                    _fail(f"interrupted: the finished rows are in {journal.path} (continue with --resume)", 130)
                journal.close(remove=True)
        if not ctx.obj["quiet"]:
            attrs = made.attributes
            click.echo(
                f"table          {shape} over xi R*/(mu a) = {lo:g} .. {hi:g}, "
                f"error estimate {made.error_bound:.3g} (tolerance {tolerance:g}), {attrs['cases']} solves, "
                f"{attrs['time']:.2f} s\n  written        {out}"
            )
        if not made.attributes["met"]:
            estimate = made.error_bound
            _fail(f"{case_file}: the error estimate {estimate:.3g} did not meet {tolerance:g} (written {out})", 1)

    try:
        _run(action)
    except KeyboardInterrupt:
        _fail("interrupted: nothing was written", 130)


@main.command()
@verbosity_options
@click.argument("case_file", type=click.Path(dir_okay=False))
@click.option(
    "--set",
    "settings",
    multiple=True,
    metavar="KEY=VALUES",
    help="A dotted case key and its values: a comma list or start:stop:count. Repeat for more keys.",
)
@click.option("--zip", "zipped", is_flag=True, help="Pair the --set lists instead of taking their product.")
@click.option(
    "--curve",
    type=click.Choice(["load", "creep"]),
    help="Creep-force curve: sweep Q/(mu P) over -0.99..0.99 (with falling friction: through both turning "
    "points, both branches), or the creepage over 1.5x full slip; "
    "with --set, one curve per combination of the set values (a family).",
)
@click.option("--points", type=click.IntRange(2, 10000), default=41, show_default=True, help="Points of --curve.")
@click.option("-o", "--output", type=click.Path(dir_okay=False), help="Sweep file (.h5).")
@click.option(
    "--workers", type=click.IntRange(1, 256), default=None, help="Worker processes [default: the usable CPUs]."
)
@click.option(
    "--scheduler",
    metavar="ADDRESS",
    help="Run on a Dask cluster: tcp://HOST:PORT, or local:N for a local cluster of N workers.",
)
@click.option("--resume", is_flag=True, help="Continue the output file: skip the cases already in it.")
@click.option("--overwrite", is_flag=True, help="Replace an existing output file (and figure).")
@click.option("--no-warm-start", is_flag=True, help="Start every case cold (for comparison).")
@click.option("--no-cache", is_flag=True, help="Neither read nor write the on-disk BEM influence cache.")
@click.option("--plot", "make_plot", is_flag=True, help="Also write a PNG figure beside the sweep file.")
@click.pass_context
def sweep(
    ctx,
    case_file,
    settings,
    zipped,
    curve,
    points,
    output,
    workers,
    scheduler,
    resume,
    overwrite,
    no_warm_start,
    no_cache,
    make_plot,
):
    """Solve CASE_FILE for every combination of swept values (or its [sweep] table)."""
    # Over 80 lines for a reason: one click command whose eleven options each map to one argument of
    # rolling_cli.study.sweep.run, with the one-line refusal of each meaningless combination next to the
    # option it names; split, the refusals would sit far from their options.

    def action():
        from .case import load_case
        from .case.io import read_toml
        from .files import outputs
        from .study import sweep as sweeps

        _imported()
        base = load_case(case_file)
        if workers and scheduler:
            raise CaseError("--workers and --scheduler: choose one; allowed: local processes or a Dask cluster")
        if ctx.get_parameter_source("points") is not click.core.ParameterSource.DEFAULT and not curve:
            raise CaseError(f"--points {points} without --curve; allowed: --points with --curve load or creep")
        if zipped and not settings:
            raise CaseError("--zip without --set; allowed: --zip pairs the values of two or more --set keys")
        if curve and settings:
            from .study.families import family_spec

            spec = family_spec(base, curve, points, sweeps.spec_from_options(list(settings), zipped))
        elif curve:
            spec = sweeps.curve_spec(base, curve, points)
        elif settings:
            spec = sweeps.spec_from_options(list(settings), zipped)
        else:
            table = read_toml(case_file).get("sweep")
            if not table:
                raise CaseError(
                    "no sweep given; allowed: --set KEY=VALUES, --curve, or a [sweep] table in the case", file=case_file
                )
            spec = sweeps.spec_from_table(table, case_file)
        out = output or Path(case_file).with_suffix("").name + "_sweep.h5"
        figure = outputs.figure_path(out) if make_plot else None
        if figure:
            outputs.check_output(figure, inputs=(case_file, out), overwrite=overwrite or resume, kind="figure")
        count = workers or sweeps.default_workers()
        signal.signal(signal.SIGTERM, _terminate)
        try:
            report = sweeps.run(
                base,
                spec,
                out,
                workers=count,
                resume=resume,
                warm=not no_warm_start,
                use_cache=not no_cache,
                progress=None if ctx.obj["quiet"] else Progress(),
                overwrite=overwrite,
                scheduler=scheduler,
                command=_command(),
            )
        except KeyboardInterrupt:
            _fail(f"interrupted: the cases finished so far are in {out} (continue with --resume)", 130)
        if figure:
            from .report.plot import plot_file

            plot_file(out, figure)
        where = f"on {scheduler}" if scheduler else f"with {count} worker(s)"
        if not ctx.obj["quiet"]:
            click.echo(sweeps.summary_table(report, spec.keys))
            click.echo(
                f"  {report.solved} cases solved ({report.skipped} already in the file), "
                f"{int(report.failed_mask.sum())} failed, {report.seconds:.2f} s {where}; written {out}"
            )
        if report.invalid and ctx.obj["q"] < 2:  # part of the result: only -qq hides it
            more = f" (and {report.invalid - 1} more cases; validity_warning in {out})" if report.invalid > 1 else ""
            click.echo(f"warning: {report.first_invalid}{more}", err=True)
        failed = int(report.failed_mask.sum())
        if failed:
            _fail(f"{failed} of {report.solved} cases failed; their reasons are in {out}", 1)

    _run(action)


def _terminate(signum, frame):  # pragma: no cover - exercised by the kill test in a subprocess
    raise KeyboardInterrupt


def entry() -> None:
    """The ``rollc`` console script (and ``python -m rolling_cli``): :func:`main`, then a quick exit.

    Garbage collection is off until the command has imported its modules (:func:`_imported`): the
    imports of a half-plane solve would trigger ~60 collections, ~10 ms, freeing ~300 objects. The
    interpreter's teardown (freeing every module of numpy, h5py and the package one by one) costs
    ~20-30 ms, a tenth of a half-plane solve's whole process, and does nothing a finished command
    needs. So once the command has returned, with the process quiet (:func:`.process.fast_exit_safe`: no
    worker machinery or plotting loaded, one thread, no HDF5 file open, so h5py's exit handler has
    nothing to close), logging is shut down (``logging.shutdown``: the one exit handler with work
    left), stdout and stderr are flushed and the process ends with the command's exit code
    (``os._exit``, the documented exit without cleanup). Otherwise, or when a flush fails (a closed
    pipe), Python exits the usual way. :func:`main` itself never ends the process early: it
    stays callable from Python and from tests.
    """
    process.reuse_freed_memory()
    gc.disable()  # until the command's imports are done (_imported): they are most of its collections
    try:
        main()
        code = 0
    except SystemExit as exit:
        code = exit.code  # type: ignore[assignment]  # None or a message: handled below
    finally:
        gc.enable()
    if not isinstance(code, int) or not process.fast_exit_safe():  # None, a message: Python's own handling
        sys.exit(code)
    logging.shutdown()
    try:
        sys.stdout.flush()
        sys.stderr.flush()
    except (OSError, ValueError):  # a closed pipe: let the usual exit report it
        sys.exit(code)
    os._exit(code)


if __name__ == "__main__":  # pragma: no cover
    entry()
