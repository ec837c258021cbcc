"""Exceptions of the solver pipeline. Only the CLI turns them into exit codes.

* :class:`CaseError` (exit 2): the case file is invalid; the message names the
  file, the dotted key, the value and what is allowed.
* :class:`GrossSlidingError` (exit 2): |Q| >= mu P, the bodies slide, they do
  not roll. A property of the input, not a solver failure.
* :class:`ConvergenceError` (exit 1): the solve failed; carries the residual,
  the iteration count, the history and the likely cause.
* :class:`ZoneError` (exit 1): the contact reached the edge of the potential
  contact zone, so the answer would be wrong.
"""

from __future__ import annotations

import re

#: Control characters (and Unicode line breaks) that would split or garble a one-line message.
CONTROL_CHARACTERS = re.compile("[\x00-\x1f\x7f-\x9f\u2028\u2029]")


class RollingError(Exception):
    """Base class of all rolling_cli errors."""


class CaseError(RollingError):
    """Invalid case input; ``str(err)`` is the one-line message."""

    def __init__(self, message: str, *, file: str | None = None, key: str | None = None) -> None:
        self.file = file
        self.key = key
        prefix = f"{file}: " if file else ""
        # file names, keys and values come from the user: escape control characters (one line)
        super().__init__(CONTROL_CHARACTERS.sub(lambda m: repr(m.group())[1:-1], prefix + message))


class GrossSlidingError(RollingError):
    """The prescribed tangential load cannot be carried by friction: |Q| >= mu P."""


class SolveError(RollingError):
    """A solve that did not give a trustworthy answer."""

    def __init__(
        self,
        message: str,
        *,
        residual: float | None = None,
        iterations: int | None = None,
        history: list | None = None,
        cause: str = "",
        partial=None,
    ) -> None:
        self.residual = residual
        self.iterations = iterations
        self.history = history or []
        self.cause = cause
        self.partial = partial
        parts = [message]
        if residual is not None:
            parts.append(f"relative residual {residual:.3e}")
        if iterations is not None:
            parts.append(f"after {iterations} Newton iterations")
        text = ", ".join(parts)
        if cause:
            text += f"; likely cause: {cause}"
        super().__init__(text)


class ConvergenceError(SolveError):
    """Newton (or the load control around it) did not converge."""


class ZoneError(SolveError):
    """The contact reaches the edge of the potential contact zone."""
