"""What the command line writes to stderr besides results: logging (``-v``/``-q`` counts before or
after the subcommand, one handler) and the sweep progress bar.

Only the CLI (:mod:`rolling_cli.cli`) sets up logging; the library only logs.
"""

from __future__ import annotations

import logging
import sys
import time

import click

#: The one handler the CLI puts on the root logger (replaced when -v/-q change after the subcommand).
_handler: logging.Handler | None = None


def log_levels(verbose: int, quiet: int) -> tuple[int, int]:
    """(rolling_cli's level, everyone else's) for ``-v``/``-q`` counts: rolling_cli's warnings by
    default and with ``-q`` (which drops the summary), its stages, strategies and timings with
    ``-v``, its debug lines with ``-vv``, errors only with ``-qq``. Third-party loggers (h5py,
    matplotlib, distributed) show warnings only, unless asked with ``-vvv``."""
    net = verbose - quiet
    ours = logging.DEBUG if net >= 2 else logging.INFO if net == 1 else logging.WARNING if net >= -1 else logging.ERROR
    theirs = logging.DEBUG if net >= 3 else logging.WARNING if net >= -1 else logging.ERROR
    return ours, theirs


class _Stderr(logging.StreamHandler):
    """A handler writing to whatever ``sys.stderr`` is when a record comes (click's test runner swaps it)."""

    @property
    def stream(self):
        return sys.stderr

    @stream.setter
    def stream(self, value) -> None:
        pass


def setup_logging(verbose: int, quiet: int) -> None:
    """Logging to stderr at the levels of :func:`log_levels` (only the CLI sets up logging)."""
    global _handler
    ours, theirs = log_levels(verbose, quiet)
    root = logging.getLogger()
    if _handler is not None:
        root.removeHandler(_handler)
    _handler = _Stderr()
    _handler.setFormatter(logging.Formatter("%(levelname)s: %(message)s"))
    root.addHandler(_handler)
    root.setLevel(theirs)
    logging.getLogger("rolling_cli").setLevel(ours)


def _verbosity(ctx: click.Context, param: click.Parameter, value: int) -> None:
    """``-v``/``-q`` after the subcommand: added to the counts given before it, logging set up again."""
    if not value or ctx.resilient_parsing:
        return
    state = ctx.find_object(dict)
    if state is None:
        return
    state[param.name] += value
    state["quiet"] = state["q"] > 0
    setup_logging(state["v"], state["q"])


def verbosity_options(command):
    """The ``-v``/``-q`` options of the group, accepted after a subcommand too (``rollc solve case.toml -q``)."""
    command = click.option(
        "-q", "--quiet", "q", count=True, expose_value=False, callback=_verbosity, help="As rollc -q."
    )(command)
    return click.option(
        "-v", "--verbose", "v", count=True, expose_value=False, callback=_verbosity, help="As rollc -v."
    )(command)


class Progress:
    """A one-line progress bar on stderr; silent when stderr is not a terminal."""

    def __init__(self, stream=None) -> None:
        self.stream = stream or sys.stderr
        self.active = self.stream.isatty()
        self.start = time.perf_counter()

    def __call__(self, done: int, total: int, failed: int) -> None:
        if not self.active:
            return
        width = 30
        filled = int(width * done / max(total, 1))
        bar = "#" * filled + "-" * (width - filled)
        extra = f", {failed} failed" if failed else ""
        self.stream.write(f"\r  sweep [{bar}] {done}/{total}{extra}, {time.perf_counter() - self.start:.1f} s")
        self.stream.flush()
        if done >= total:
            self.stream.write("\n")
