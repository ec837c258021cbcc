"""The BEM influence cache proves what it holds (issue #15, item 7): every damaged,
foreign or inconsistent entry is reported once, deleted and recomputed, and the
answer is the one computed without the cache."""

import logging
import shutil

import numpy as np
import pytest

from helpers import case_dict, run_cli, write_case
from rolling_cli import solve
from rolling_cli.case import load_case
from rolling_cli.influence import build, cache


@pytest.fixture
def cache_dir(tmp_path, monkeypatch):
    directory = tmp_path / "cache"
    monkeypatch.setenv("ROLLC_CACHE_DIR", str(directory))
    build.clear_memo()
    yield directory
    build.clear_memo()


def _case(young: float = 210000.0):
    return load_case(
        case_dict(
            **{
                "discretization.influence": "bem",
                "discretization.contact_elements": 12,
                "bodies.A.young": young,
                "bodies.B.young": young,
            }
        )
    )


def _solve(case):
    build.clear_memo()  # the in-process memo would hide the disk
    return solve(case)


@pytest.fixture
def reference(cache_dir):
    """The cache-free answer, then one entry on disk: (result, entry path, its bytes)."""
    case = _case()
    fresh = solve(case, use_cache=False)
    _solve(case)
    (entry,) = cache_dir.glob("*.npz")
    return fresh, entry, entry.read_bytes()


def _from_cache(result) -> bool:
    return "from disk cache" in result.effects_line


def _check_recovery(entry, fresh, caplog):
    """The bad entry gives one warning, the cache-free answer and a new, valid entry."""
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger="rolling_cli.influence.cache"):
        first = _solve(_case())
        second = _solve(_case())
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert len(warnings) == 1 and "invalid influence cache entry" in warnings[0], warnings
    assert "deleted, recomputing" in warnings[0]
    assert not _from_cache(first) and _from_cache(second)
    for result in (first, second):
        assert np.array_equal(result.p_n, fresh.p_n) and np.array_equal(result.p_t, fresh.p_t)
        assert result.normal_load == fresh.normal_load
    assert cache.load_entry(entry, _entry_inputs()) is not None
    return warnings[0]


def _entry_inputs() -> dict:
    from rolling_cli import pipeline

    case = _case()
    the_plan = pipeline.plan(case)
    return build.bem_inputs(case, the_plan, case.bodies.A)


def test_clean_entry_is_used(reference):
    fresh, entry, _ = reference
    again = _solve(_case())
    assert _from_cache(again) and np.array_equal(again.p_t, fresh.p_t)


@pytest.mark.parametrize("where", [0.1, 0.5, 0.9])
def test_flipped_byte(reference, caplog, where):
    fresh, entry, data = reference
    damaged = bytearray(data)
    damaged[int(where * len(damaged))] ^= 0x01
    entry.write_bytes(bytes(damaged))
    _check_recovery(entry, fresh, caplog)


@pytest.mark.parametrize("keep", [0, 22, 0.5])
def test_truncated_or_empty(reference, caplog, keep):
    fresh, entry, data = reference
    entry.write_bytes(data[: int(keep * len(data)) if isinstance(keep, float) else keep])
    message = _check_recovery(entry, fresh, caplog)
    assert "unreadable" in message


def test_entry_of_another_case(reference, caplog, cache_dir):
    """The issue's swap: an E = 70000 entry under this case's name gave P = 169.7 instead of 509.2."""
    fresh, entry, _ = reference
    shutil.move(entry, cache_dir / "own.bak")
    _solve(_case(young=70000.0))
    (other,) = [p for p in cache_dir.glob("*.npz")]
    shutil.copy(other, entry)
    message = _check_recovery(entry, fresh, caplog)
    assert "written for another case" in message


def _rewrite(entry, change, recompute_checksum: bool):
    """Rewrite an entry's arrays through ``change``, keeping (or recomputing) its checksum."""
    with np.load(entry) as data:
        items = {name: data[name] for name in data.files}
    arrays = {name: items[name] for name in cache._ARRAYS}
    arrays = change(arrays)
    if recompute_checksum:
        items["checksum"] = np.asarray(cache.checksum(arrays))
    items.update(arrays)
    with open(entry, "wb") as handle:
        np.savez(handle, **items)


def test_changed_values_fail_the_checksum(reference, caplog):
    fresh, entry, _ = reference
    _rewrite(entry, lambda a: {**a, "S_nn": a["S_nn"] * (1 + 1e-12)}, recompute_checksum=False)
    assert "checksum mismatch" in _check_recovery(entry, fresh, caplog)


def test_wrong_node_count_is_refused_even_with_a_valid_checksum(reference, caplog):
    """An entry three nodes short, internally consistent: its nodes are not its key's grid."""
    fresh, entry, _ = reference

    def short(a):
        out = {name: a[name][:-3] for name in ("x", "weights")}
        out.update({name: a[name][:-3, :-3] for name in cache._BLOCKS})
        return {**a, **out}

    _rewrite(entry, short, recompute_checksum=True)
    message = _check_recovery(entry, fresh, caplog)
    assert "33 nodes that are not the 36 contact nodes of its key" in message


def test_non_finite_values_are_refused(reference, caplog):
    fresh, entry, _ = reference
    _rewrite(entry, lambda a: {**a, "S_tt": np.where(np.eye(36, dtype=bool), np.nan, a["S_tt"])}, True)
    assert "non-finite values" in _check_recovery(entry, fresh, caplog)


def test_old_layout_is_replaced(reference, caplog):
    """An entry of the previous layout (no recorded key or checksum) is recomputed once."""
    fresh, entry, _ = reference
    with np.load(entry) as data:
        arrays = {name: data[name] for name in cache._ARRAYS}
    with open(entry, "wb") as handle:
        np.savez(handle, **arrays)
    assert "not an entry of this rollc version" in _check_recovery(entry, fresh, caplog)


def test_cli_recovers_from_an_empty_entry(reference, tmp_path):
    """The issue's 0-byte entry printed only "Aborted!" (click's EOFError)."""
    fresh, entry, _ = reference
    entry.write_bytes(b"")
    build.clear_memo()
    data = case_dict(**{"discretization.influence": "bem", "discretization.contact_elements": 12})
    result = run_cli("solve", write_case(tmp_path, data), "-o", tmp_path / "o.h5")
    assert result.exit_code == 0, result.output
    assert "Aborted" not in result.output and "converged      yes" in result.output
    assert entry.stat().st_size > 0


def test_failed_write_leaves_no_partial_entry(cache_dir, monkeypatch, caplog):
    """A write that fails half way (a full disk) leaves neither a temporary file nor an
    entry, and the solve itself succeeds."""
    real = np.savez

    def failing(handle, **arrays):
        real(handle, **arrays)
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(np, "savez", failing)
    with caplog.at_level(logging.WARNING, logger="rolling_cli.influence.cache"):
        result = _solve(_case())
    assert result.converged
    assert list(cache_dir.iterdir()) == []
    assert any("No space left on device" in r.getMessage() for r in caplog.records)
