"""Every documented command is a test: each ``$ rollc ...`` line of README.md's console blocks.

The lines run in order, as a user types them (a ``rollc`` process each, in one
scratch directory holding a copy of the shipped ``cases/``), so a later line
may use a file an earlier one wrote. Each must exit 0, and every file it names
with ``-o`` must exist afterwards. Sweeps run with warm starts on (the default).
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def console_commands(text: str) -> list[str]:
    """The ``$ rollc ...`` lines of the ```console blocks of a Markdown text, in order."""
    commands = []
    for block in re.findall(r"```console\n(.*?)```", text, flags=re.S):
        for line in block.splitlines():
            if line.startswith("$ rollc"):
                commands.append(line[2:].strip())
    return commands


COMMANDS = console_commands((ROOT / "README.md").read_text())


def _argv(command: str) -> list[str]:
    words = shlex.split(command, comments=True)
    rollc = shutil.which("rollc")
    return ([rollc] if rollc else [sys.executable, "-m", "rolling_cli"]) + words[1:]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Run every README command in order in one directory; returns {command: (CompletedProcess, workdir)}."""
    work = tmp_path_factory.mktemp("readme")
    shutil.copytree(ROOT / "cases", work / "cases")
    env = {**os.environ, "ROLLC_CACHE_DIR": str(work / "cache")}
    out = {}
    for command in COMMANDS:
        out[command] = subprocess.run(_argv(command), cwd=work, env=env, capture_output=True, text=True, timeout=600)
    return out, work


def test_the_readme_documents_commands():
    assert len(COMMANDS) >= 8
    assert any(c.startswith("rollc solve") for c in COMMANDS)
    assert any("--curve load" in c for c in COMMANDS)


@pytest.mark.parametrize("command", COMMANDS)
def test_documented_command_exits_0(runs, command):
    results, work = runs
    done = results[command]
    assert done.returncode == 0, f"{command!r} exited {done.returncode}:\n{done.stdout[-2000:]}\n{done.stderr[-2000:]}"
    words = shlex.split(command, comments=True)
    for flag in ("-o", "--output"):
        if flag in words:
            assert (work / words[words.index(flag) + 1]).exists(), f"{command!r} did not write its -o file"
