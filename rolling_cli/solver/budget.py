"""The iteration budget shared by every strategy of one solve.

One small object replaces a counter in a closure and every "half the budget"
rule: each Newton iteration (one linear solve) is taken from it, every
iterate's record is appended to its history, and a strategy that runs out
stops with its best state so that the next strategy (or the error message)
can use it.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

log = logging.getLogger(__name__)


class BudgetExhausted(Exception):
    """Raised by :meth:`Budget.take` when no iteration is left."""


@dataclass
class Budget:
    """``limit`` Newton iterations in all; ``taken`` so far; ``history`` one dict per iterate.

    History rows carry at least ``strategy``, ``stage``, ``iteration`` (within the
    stage) and ``residual``; the formulation adds its own columns.
    """

    limit: int
    taken: int = 0
    history: list[dict] = field(default_factory=list)

    @property
    def exhausted(self) -> bool:
        """True when no iteration is left."""
        return self.taken >= self.limit

    def take(self) -> None:
        """Spend one iteration; raises :class:`BudgetExhausted` when none is left."""
        if self.exhausted:
            raise BudgetExhausted(f"the iteration budget of {self.limit} is spent")
        self.taken += 1

    def record(self, row: dict) -> None:
        """Append one history row (a debug log line: ``rollc -vv``)."""
        self.history.append(row)
        if log.isEnabledFor(logging.DEBUG):
            log.debug("Newton %s", ", ".join(f"{k} {_short(v)}" for k, v in row.items()))

    def strategies(self) -> list[str]:
        """The strategies that ran, in order of first appearance."""
        seen: list[str] = []
        for row in self.history:
            name = row.get("strategy", "")
            if name and name not in seen:
                seen.append(name)
        return seen


def _short(value) -> str:
    return f"{value:.3e}" if isinstance(value, float) else str(value)
