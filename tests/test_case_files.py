"""Reading case files (issue #15, item 5): regular files only, a size cap, every
parse failure as the one-line error, nothing that blocks or floods memory."""

import os
import shutil
import subprocess
import sys
import threading

import pytest
import tomli_w

from helpers import CARTER, run_cli, write_case
from rolling_cli.case import load_case
from rolling_cli.case.io import MAX_CASE_BYTES
from rolling_cli.errors import CaseError


def _error(path) -> str:
    with pytest.raises(CaseError) as info:
        load_case(path)
    message = str(info.value)
    assert "\n" not in message and message.startswith(f"{path}: ")
    return message


def _cli_error(*args) -> str:
    result = run_cli(*args)
    assert result.exit_code == 2, result.output
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exception
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.output
    return lines[0]


def test_fifo_is_refused_without_blocking(tmp_path):
    """A FIFO with no writer would block a plain open() forever."""
    fifo = tmp_path / "case.toml"
    os.mkfifo(fifo)
    outcome = {}

    def read():
        try:
            load_case(fifo)
        except CaseError as err:
            outcome["message"] = str(err)

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    reader.join(timeout=30.0)
    if reader.is_alive():  # release the blocked reader before failing
        os.close(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK))
        pytest.fail("reading a FIFO blocked")
    assert "is a FIFO (named pipe); allowed: a regular TOML case file" in outcome["message"]
    assert "is a FIFO" in _cli_error("check", fifo)


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/null", "/dev/urandom"])
def test_devices_are_refused(device):
    if not os.path.exists(device):
        pytest.skip(f"{device} does not exist here")
    assert "is a character device" in _error(device)
    assert "is a character device" in _cli_error("solve", device)


def test_directory_is_refused(tmp_path):
    assert "is a directory" in _error(tmp_path)


def test_size_cap(tmp_path):
    """A valid case padded with comments to exactly the cap loads; one byte more is refused."""
    text = tomli_w.dumps(CARTER)
    path = tmp_path / "case.toml"
    padding = MAX_CASE_BYTES - len(text.encode())
    path.write_text(text + "#" * (padding - 1) + "\n")
    assert path.stat().st_size == MAX_CASE_BYTES
    assert load_case(path).friction.mu == 0.1
    path.write_text(text + "#" * padding + "\n")
    assert f"too large ({MAX_CASE_BYTES + 1} bytes)" in _error(path)
    assert "too large" in _cli_error("check", path)


@pytest.mark.parametrize(
    "nested",
    [
        "x = " + "[" * 3000 + "]" * 3000,
        "x = " + "{a = " * 3000 + "1" + "}" * 3000,
        "x = [" + "{a = [" * 1500 + "]}" * 1500 + "]",
    ],
    ids=["arrays", "inline tables", "mixed"],
)
def test_deep_nesting_is_the_one_line_error(tmp_path, nested):
    """Python's TOML parser recurses once per level and raises RecursionError."""
    path = tmp_path / "case.toml"
    path.write_text(nested + "\n")
    assert "nested too deeply" in _error(path)
    assert "nested too deeply" in _cli_error("solve", path)


def test_moderate_nesting_in_an_unknown_key_is_reported_as_unknown(tmp_path):
    path = write_case(tmp_path, CARTER)
    path.write_text(path.read_text() + "\n[extra]\nx = " + "[" * 200 + "]" * 200 + "\n")
    assert "extra = {x}: unknown key" in _error(path)


def test_other_parse_failures(tmp_path):
    path = tmp_path / "case.toml"
    path.write_text("x = " + "9" * 5000 + "\n")  # beyond Python's integer-string limit (ValueError)
    assert "invalid TOML" in _error(path)
    path.write_bytes(b'title = "\xff\xfe"\n')
    assert "not UTF-8 text (byte 0xff at offset 9)" in _error(path)
    path.write_text("[friction]\nmu = 0.1\nmu = 0.2\n")
    assert "invalid TOML (Cannot overwrite a value" in _error(path)
    path.write_text("title = 1979-05-27T07:32:00Z\n" + tomli_w.dumps({k: v for k, v in CARTER.items() if k != "title"}))
    assert "title = datetime.datetime(1979, 5, 27, 7, 32" in _error(path)  # valid TOML, not a string


def test_byte_order_mark_is_accepted(tmp_path):
    path = tmp_path / "case.toml"
    path.write_bytes(b"\xef\xbb\xbf" + tomli_w.dumps(CARTER).encode())
    assert load_case(path).normal.load == 1812.5


def test_control_characters_never_break_the_line(tmp_path):
    """Keys, values and file names come from the user: they are escaped in the message."""
    data = {**CARTER, "friction": {"mu": 0.1, "bad\nkey\x1b[31m": 1.0}}
    message = _error(write_case(tmp_path, data))
    assert "friction.bad\\nkey\\x1b[31m = 1.0: unknown key" in message
    odd = write_case(tmp_path, {**CARTER, "title": "two\nlines"}, name="odd\nname.toml")
    message = str(pytest.raises(CaseError, load_case, odd).value)
    assert "\n" not in message and "odd\\nname.toml" in message and 'title = "two\\nlines"' in message


def test_unreadable_paths(tmp_path):
    assert "file not found" in _error(tmp_path / "missing.toml")
    assert "cannot read (Not a directory)" in _error(write_case(tmp_path, CARTER) / "below")
    with pytest.raises(CaseError, match="invalid path"):
        load_case(str(tmp_path / "nul\0byte.toml"))


def test_permission_denied(tmp_path):
    """A case file nobody may read. Root reads any file through CAP_DAC_OVERRIDE, so as root the check
    runs in a subprocess whose capability bounding set lacks it (util-linux setpriv): a real denial."""
    path = write_case(tmp_path, CARTER)
    path.chmod(0)
    if os.geteuid() != 0:
        assert "cannot read (Permission denied)" in _error(path)
        return
    setpriv = shutil.which("setpriv")
    assert setpriv, "setpriv (util-linux) is needed to drop root's file-access override"
    code = (
        "import sys\nfrom rolling_cli.case import load_case\nfrom rolling_cli.errors import CaseError\n"
        f"try:\n    load_case({str(path)!r})\nexcept CaseError as err:\n    print(err)\n"
    )
    done = subprocess.run(
        [setpriv, "--bounding-set=-dac_override,-dac_read_search", sys.executable, "-c", code],
        capture_output=True,
        text=True,
        check=True,
    )
    assert "cannot read (Permission denied)" in done.stdout
