"""Mutated case files (issue #15, item 11): hypothesis damages valid case files
(their TOML structure and their raw bytes) and feeds them to ``load_case``, to
``rollc check`` and, when the result is a valid and cheap case, to ``rollc
solve``. The only outcomes allowed: a valid Case (and a solve that passes the
contact-law check or fails with its one-line message), or the one-line error
with exit code 2. Never a traceback, never another exception. A fixed seed and
no example database make the run reproducible."""

import datetime
import tomllib

import numpy as np
import tomli_w
from hypothesis import HealthCheck, event, given, seed, settings
from hypothesis import strategies as st

from helpers import CARTER, assert_contact_laws, case_dict, dissimilar, run_cli
from rolling_cli.case import load_case
from rolling_cli.errors import CaseError
from rolling_cli.files.io_hdf5 import read_result
from rolling_cli.pipeline import resources

SMALL = {"discretization.contact_elements": 20}
BASES = [
    tomli_w.dumps(case_dict(CARTER, **SMALL)),
    tomli_w.dumps(dissimilar(**SMALL, **{"tangential.creep": -4e-4})),
    tomli_w.dumps(
        case_dict(
            **{
                "bodies.A": {"kind": "rigid", "radius": 100.0},
                "bodies.B": {"kind": "layered", "radius": 100.0, "young": 10.0, "poisson": 0.5, "layer_thickness": 0.3},
                "normal.overlap": 0.0042,
                "discretization.influence": "bem",
                "discretization.contact_elements": 20,
            },
        )
    ),
]

KEYS = [
    "title",
    "bodies.A.kind",
    "bodies.A.radius",
    "bodies.A.young",
    "bodies.B.poisson",
    "bodies.B.layer_thickness",
    "friction.mu",
    "normal.load",
    "normal.overlap",
    "tangential.q_over_mu_p",
    "tangential.q_over_p",
    "tangential.load",
    "tangential.creep",
    "rolling.direction",
    "discretization.influence",
    "discretization.contact_elements",
    "discretization.zone",
    "discretization.element",
    "discretization.slip_derivative",
    "solver.tolerance",
    "solver.max_iterations",
    "solver.penalty",
    "effects.coupling",
    "units.length",
    "output.file",
    "sweep.friction.mu",
    "friction.nu",
    "bodies",
    "normal",
]

EXTREMES = [0.0, -0.0, 5e-324, 1e-300, 1e-30, 1e-14, 1e-6, 1e-3, 0.5, 0.999, 1.0, 2.0, 100.0, 1e30, 1e300, 1.8e308]
VALUES = st.one_of(
    st.sampled_from(EXTREMES),
    st.sampled_from(EXTREMES).map(lambda v: -v),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(2**80), max_value=2**80),
    st.text(max_size=12),
    st.sampled_from(["inf", "auto", "bem", "half-plane", "layered", "rigid", "constant", "element", "on"]),
    st.booleans(),
    st.lists(st.integers(min_value=-3, max_value=3), max_size=3),
    st.dictionaries(st.sampled_from(["mu", "load", "x"]), st.floats(allow_nan=False), max_size=2),
    st.datetimes(min_value=datetime.datetime(1900, 1, 1), max_value=datetime.datetime(2100, 1, 1)),
)


def _set(data: dict, dotted: str, value) -> dict:
    node = data
    parts = dotted.split(".")
    for part in parts[:-1]:
        child = node.get(part)
        if not isinstance(child, dict):
            child = node[part] = {}
        node = child
    if value is None:
        node.pop(parts[-1], None)
    else:
        node[parts[-1]] = value
    return data


@st.composite
def structural(draw, text: str) -> bytes:
    """Keys set to values of any TOML type (or removed), written back as TOML."""
    data = tomllib.loads(text)
    for _ in range(draw(st.integers(1, 3))):
        value = draw(st.one_of(st.none(), VALUES))
        _set(data, draw(st.sampled_from(KEYS)), value)
    return tomli_w.dumps(data).encode()


SNIPPETS = [
    b"[",
    b"]]",
    b"=",
    b'"',
    b"\n[bodies]\n",
    b"\n[friction]\nmu = 0.2\n",
    b"\x00",
    b"\xff\xfe",
    b"\r",
    b"{",
    b"'''",
]


@st.composite
def textual(draw, text: str) -> bytes:
    """The raw bytes damaged: slices deleted, snippets or random bytes inserted, lines repeated."""
    data = bytearray(text.encode())
    for _ in range(draw(st.integers(1, 3))):
        where = draw(st.integers(0, len(data)))
        op = draw(st.sampled_from(["delete", "insert", "bytes", "repeat", "truncate"]))
        if op == "delete":
            del data[where : where + draw(st.integers(1, 20))]
        elif op == "insert":
            data[where:where] = draw(st.sampled_from(SNIPPETS))
        elif op == "bytes":
            data[where:where] = draw(st.binary(min_size=1, max_size=4))
        elif op == "repeat":
            lines = bytes(data).splitlines(keepends=True)
            if lines:
                k = draw(st.integers(0, len(lines) - 1))
                lines.insert(k, lines[k])
                data = bytearray(b"".join(lines))
        else:
            del data[where:]
    return bytes(data)


NUMERIC = {
    "bodies.A.radius": (1e-30, 1e30),
    "bodies.B.radius": (1e-30, 1e30),
    "bodies.A.young": (1e-30, 1e30),
    "bodies.B.young": (1e-30, 1e30),
    "bodies.B.layer_thickness": (1e-30, 1e30),
    "friction.mu": (1e-6, 100.0),
    "normal.load": (1e-30, 1e30),
    "normal.overlap": (1e-30, 1e30),
    "tangential.q_over_mu_p": (1e-9, 0.999999),
    "tangential.creep": (1e-16, 1.0),
    "solver.tolerance": (1e-14, 1e-3),
    "solver.penalty": (1e-30, 1e30),
    "discretization.zone": (1.0001, 20.0),
}


@st.composite
def numeric(draw, text: str) -> bytes:
    """Accepted-looking numbers, log-uniform over their ranges (and a little beyond): the
    mutations that reach the solver."""
    data = tomllib.loads(text)
    for _ in range(draw(st.integers(1, 3))):
        key = draw(st.sampled_from(sorted(NUMERIC)))
        low, high = NUMERIC[key]
        exponent = draw(st.floats(np.log10(low) - 1.0, np.log10(high) + 0.2))
        sign = -1.0 if key.startswith("tangential") and draw(st.booleans()) else 1.0
        _set(data, key, sign * float(10.0**exponent))
    return tomli_w.dumps(data).encode()


MUTATED = st.sampled_from(BASES).flatmap(
    lambda text: st.one_of(structural(text), textual(text), numeric(text), numeric(text))
)


def _clean_failure(result, codes) -> str:
    assert result.exception is None or isinstance(result.exception, SystemExit), repr(result.exception)
    assert result.exit_code in codes, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.output
    return lines[0]


def _cheap(case) -> bool:
    found = resources.estimate(case)
    return found.bytes < 100e6 and found.flops < 2e9


@seed(15)
@settings(
    max_examples=60,
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(content=MUTATED)
def test_mutated_case_files(tmp_path, content):
    path = tmp_path / "case.toml"
    path.write_bytes(content)
    try:
        case = load_case(path)
    except CaseError as err:
        message = str(err)
        assert "\n" not in message and message.startswith(f"{path}: "), message
        event(f"refused: {message[len(str(path)) + 2 :].split(' = ')[0].split(' (')[0][:30]}")
        case = None

    if case is None:
        assert str(path) in _clean_failure(run_cli("check", path), (2,))
        return
    if not _cheap(case):
        event("valid, too costly to check and solve here")
        return
    checked = run_cli("check", path)
    if checked.exit_code != 0:
        # gross sliding (2), more memory than the machine has (2), a failed pre-solve (1)
        event(f"valid, check exit {checked.exit_code}")
        _clean_failure(checked, (1, 2))
        return
    out = tmp_path / "result.h5"
    out.unlink(missing_ok=True)
    solved = run_cli("-q", "solve", path, "-o", out)
    event(f"valid, solve exit {solved.exit_code}")
    if solved.exit_code == 0:
        assert solved.exception is None or isinstance(solved.exception, SystemExit), repr(solved.exception)
        assert_contact_laws(read_result(out), case.solver.tolerance)
    else:
        _clean_failure(solved, (1, 2))
        assert not out.exists()
