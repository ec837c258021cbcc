"""``python -m rolling_cli`` is ``rollc``."""

from .cli import entry

entry()
