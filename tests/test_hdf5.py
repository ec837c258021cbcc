"""The result file layout (format 2), relied on by other tools: xarray opens every kind of file
as is, and what it shows is the solver's own result, bit for bit."""

import os
import tomllib
from pathlib import Path

import h5py
import numpy as np
import pytest

from helpers import CARTER, case_dict, dissimilar, solve
from rolling_cli import blas
from rolling_cli.case import load_case
from rolling_cli.files.io_hdf5 import read_result, write_result
from rolling_cli.files.rows import GROUP_HOOKS, GroupHook, Row, row_from_result
from rolling_cli.files.writer import ResultFile
from rolling_cli.study import sweep

xr = pytest.importorskip("xarray")
pytest.importorskip("h5netcdf")

DATA = Path(__file__).parent / "data"
SMALL = case_dict(**{"discretization.contact_elements": 40})
NODE_FIELDS = ("p_n", "p_t", "delta_n", "s_t", "state")


def _solver_records(base, spec, warm=True):
    """The solver's own records of a sweep: the chunks solved directly, as the sweep solves them."""
    items = [(i, combo, sweep.build(base, combo)) for i, combo in enumerate(spec.combinations())]
    with blas.single_threaded():
        return [record for chunk in sweep.chunks(items) for record in sweep.solve_chunk(chunk, warm, True)]


def test_single_result_opens_in_xarray_with_units_and_the_solvers_values(tmp_path):
    result = solve(SMALL)
    path = tmp_path / "r.h5"
    write_result(result, path)
    ds = xr.open_dataset(path)  # no options: dimension scales, CF attributes, decodable types
    n = result.x.size
    assert dict(ds.sizes) == {"case": 1, "node": n}
    assert list(ds.case.values) == [0] and ds.x.dims == ("node",) and "x" in ds.p_t.coords
    for name in (*NODE_FIELDS, "weights"):
        assert ds[name].dims == (("case", "node") if name != "weights" else ("node",))
        values = ds[name].values[0] if name != "weights" else ds[name].values
        assert np.array_equal(values, getattr(result, name)), name
        assert values.dtype == getattr(result, name).dtype, name
    assert np.array_equal(ds.x.values, result.x)
    assert ds.p_n.attrs["units"] == "N/mm^2" and ds.x.attrs["units"] == "mm" and "long_name" in ds.p_t.attrs
    assert ds.normal_load.attrs["units"] == "N/mm" and ds.creep.attrs["units"] == "1"
    assert ds.state.attrs["flag_meanings"] == "separation adhesion slip"
    assert list(ds.state.attrs["flag_values"]) == [0, 1, 2]
    assert ds.converged.dtype == bool and bool(ds.converged[0])
    for name in ("normal_load", "tangential_load", "creep", "mu", "hertz_a", "hertz_p0", "residual", "iterations"):
        assert ds[name].values[0] == result.attributes[name], name
    assert str(ds.message.values[0]) == "" and str(ds.influence.values[0]) == "half-plane"
    assert ds.attrs["Conventions"] == "CF-1.8" and ds.attrs["format_version"] == 2
    assert ds.attrs["cases_complete"] == 1 and ds.attrs["created"].endswith("+00:00")
    assert "rolling_cli" in ds.attrs["history"] and ds.attrs["source"].startswith("rolling_cli")
    assert tomllib.loads(ds.attrs["case"])["tangential"]["q_over_mu_p"] == 0.51
    # Q is the weighted sum of the tangential traction, as documented
    assert np.isclose(ds.weights.values @ ds.p_t.values[0], ds.tangential_load.values[0], rtol=1e-12)
    conv = xr.open_dataset(path, group="convergence")
    assert list(conv.residual.values) == [row["residual"] for row in result.history]
    assert list(conv.stage.values) == [row["stage"] for row in result.history]
    assert set(conv.case_index.values) == {0} and conv.case_index.attrs["instance_dimension"] == "case"
    assert ds.history_rows.values[0] == len(result.history) and ds.nodes.values[0] == n


def test_read_result_round_trip(tmp_path):
    result = solve(CARTER)
    path = tmp_path / "r.h5"
    write_result(result, path)
    back = read_result(path)
    for name in (*NODE_FIELDS, "x", "weights"):
        assert np.array_equal(getattr(back, name), getattr(result, name)), name
    for key, value in result.attributes.items():
        if key == "format_version":
            continue
        stored = back.attributes[key]
        assert stored == value or (isinstance(value, float) and np.isnan(value) and np.isnan(stored)), key
    assert back.reference.keys() == result.reference.keys()
    assert np.array_equal(back.reference["carter_traction"], result.reference["carter_traction"])
    for row, stored in zip(result.history, back.history, strict=True):
        assert all(stored[k] == v for k, v in row.items())
    assert back.case_toml == result.case_toml


def test_sweep_file_is_one_tidy_table(tmp_path):
    """The issue's one-liners: open_dataset, to_dataframe, and ds.p_t.sel(case=ds.mu == 0.3)."""
    base = load_case(SMALL)
    spec = sweep.spec_from_options(["friction.mu=0.1:0.4:4"], False)  # 0.3 exactly, not 0.30000000000000004
    path = tmp_path / "study.h5"
    sweep.run(base, spec, path)
    records = _solver_records(base, spec)
    ds = xr.open_dataset(path)
    assert dict(ds.sizes) == {"case": 4, "node": records[0].result.x.size}
    assert list(ds.friction_mu.values) == [0.1, 0.2, 0.3, 0.4] and "friction_mu" in ds.coords
    assert ds.friction_mu.attrs["case_key"] == "friction.mu"
    assert ds.x.dims == ("node",)  # every case shares the grid
    selected = ds.p_t.sel(case=ds.mu == 0.3)
    assert selected.shape == (1, ds.sizes["node"])
    assert np.array_equal(selected.values[0], records[2].result.p_t)  # bit for bit, the solver's own record
    for record in records:
        for name in NODE_FIELDS:
            assert np.array_equal(ds[name].values[record.index], getattr(record.result, name)), name
        assert ds.creep.values[record.index] == record.result.creep
    table = ds.to_dataframe()
    assert len(table) == 4 * ds.sizes["node"] and {"p_t", "friction_mu", "mu", "converged"} <= set(table.columns)
    assert ds.attrs["sweep_keys"] == '["friction.mu"]' and ds.attrs["cases_total"] == 4


def test_failed_cases_are_rows_with_a_reason(tmp_path):
    base = load_case(SMALL)
    spec = sweep.spec_from_options(["solver.max_iterations=100,1,100"], False)  # case 1 fails in the run
    path = tmp_path / "s.h5"
    report = sweep.run(base, spec, path, warm=False)
    assert int(report.failed_mask.sum()) == 1
    ds = xr.open_dataset(path)
    assert list(ds.converged.values) == [True, False, True]
    assert str(ds.message.values[1]).startswith("sweep case (solver.max_iterations = 1): ")
    assert str(ds.message.values[0]) == ""
    assert np.all(np.isnan(ds.p_t.values[1])) and np.all(ds.state.values[1] == -1)
    assert ds.iterations.values[1] == -1 and np.isnan(ds.normal_load.values[1])
    assert ds.solver_max_iterations.values[1] == 1


def test_grids_that_differ_are_per_case_and_padded(tmp_path):
    base = load_case(SMALL)
    spec = sweep.spec_from_options(["discretization.contact_elements=10,20"], False)
    path = tmp_path / "s.h5"
    sweep.run(base, spec, path)
    records = _solver_records(base, spec)
    ds = xr.open_dataset(path)
    assert ds.sizes["node"] == 60 and ds.x.dims == ("case", "node")  # quadratic elements: 3 nodes each
    assert list(ds.nodes.values) == [30, 60]
    for record in records:
        n = record.result.x.size
        assert np.array_equal(ds.x.values[record.index, :n], record.result.x)
        assert np.array_equal(ds.p_n.values[record.index, :n], record.result.p_n)
        assert np.all(np.isnan(ds.p_n.values[record.index, n:])) and np.all(ds.state.values[record.index, n:] == -1)


def test_a_grid_that_changes_later_turns_x_per_case(tmp_path):
    """x starts one-dimensional; a later case on another grid rebuilds it as (case, node), rows kept."""
    first, second = solve(SMALL), solve(case_dict(SMALL, **{"normal.load": 900.0}))
    path = str(tmp_path / "s.h5")
    writer = ResultFile(path, {"format": "rolling_cli.result", "format_version": 2}, ("normal.load",), total=2)
    writer.add(row_from_result(first, 0, {"normal.load": 1812.5}))
    writer.commit()
    with h5py.File(path) as f:
        assert f["x"].ndim == 1
    writer.add(row_from_result(second, 1, {"normal.load": 900.0}))
    writer.close()
    ds = xr.open_dataset(path)
    assert ds.x.dims == ("case", "node")
    assert np.array_equal(ds.x.values[0], first.x) and np.array_equal(ds.x.values[1], second.x)
    assert ds.normal_load_set.attrs["case_key"] == "normal.load"  # the solved P keeps its own name
    assert ds.normal_load.values[1] == second.normal_load


def test_appends_write_in_place_and_scalars_of_any_kind(tmp_path):
    """A commit that fits writes rows into the file as it is (same inode: no copy; the size grows only
    by the global heap that holds the new rows' variable-length texts); new scalars and number kinds
    that change rebuild it, keeping the rows."""
    result = solve(SMALL)
    path = str(tmp_path / "s.h5")
    writer = ResultFile(path, {"format": "rolling_cli.result", "format_version": 2}, total=40)
    for i in range(3):
        writer.add(row_from_result(result, i, extra=i, label="a"))
    writer.commit()
    before = os.stat(path)
    for i in range(3, 6):
        writer.add(row_from_result(result, i, extra=i, label="b"))
    writer.commit()
    after = os.stat(path)
    assert after.st_ino == before.st_ino
    # the texts of 3 rows (a few hundred bytes) go to one new HDF5 global heap collection, 4 kB at least
    # (H5HG_MINSIZE) and 8 kB measured; the numeric rows go into space allocated before: no more growth
    assert 0 <= after.st_size - before.st_size <= 4 * 4096
    writer.add(row_from_result(result, 6, extra=0.5, label="a much longer label than before", new_flag=True))
    writer.commit()
    assert os.stat(path).st_ino != before.st_ino  # rebuilt: a new file, made while the old one existed
    writer.close()
    ds = xr.open_dataset(path)
    assert ds.sizes["case"] == 7 and list(ds.case.values) == list(range(7))
    assert ds.extra.dtype == float and list(ds.extra.values) == [0, 1, 2, 3, 4, 5, 0.5]
    assert list(ds.label.values) == ["a"] * 3 + ["b"] * 3 + ["a much longer label than before"]
    assert ds.new_flag.dtype == bool and list(ds.new_flag.values) == [False] * 6 + [True]


def test_history_columns_are_the_union_of_all_rows(tmp_path):
    result = solve(SMALL)
    path = str(tmp_path / "s.h5")
    writer = ResultFile(path, {"format": "rolling_cli.result", "format_version": 2}, total=2)
    writer.add(row_from_result(result, 0))
    changed = [{**row, "predictor": "secant"} for row in result.history]  # a column the solver does not write
    writer.add(Row(1, {}, {"converged": True, "history_rows": len(changed)}, history=changed))
    writer.close()
    conv = xr.open_dataset(path, group="convergence")
    n = len(result.history)
    assert conv.sizes["row"] == 2 * n and list(conv.case_index.values) == [0] * n + [1] * n
    assert list(conv.predictor.values) == [""] * n + ["secant"] * n
    assert list(conv.residual.values) == [r["residual"] for r in result.history] * 2


def test_extra_groups_through_their_hook(tmp_path, monkeypatch):
    def write(group, payload):
        group.create_dataset("sigma_xx", data=payload)

    monkeypatch.setitem(GROUP_HOOKS, "stresses", GroupHook(write, lambda group: group["sigma_xx"][()]))
    result = solve(SMALL)
    field = np.arange(12.0).reshape(3, 4)
    result.stresses = field
    path = tmp_path / "r.h5"
    write_result(result, path)
    assert np.array_equal(read_result(path).stresses, field)
    assert xr.open_dataset(path).sizes["case"] == 1  # the root layout is unchanged


def test_no_reference_for_dissimilar(tmp_path):
    result = solve(dissimilar(**{"discretization.contact_elements": 40}))
    path = tmp_path / "d.h5"
    write_result(result, path)
    ds = xr.open_dataset(path)
    assert "carter_traction" not in ds and ds.beta_dundurs.values[0] > 0.1


def test_format_1_files_are_still_read():
    result = read_result(DATA / "v1_result.h5")
    assert result.converged and result.x.size == 30 and result.history
    with h5py.File(DATA / "v1_sweep.h5") as f:
        assert f.attrs["format"] == "rolling_cli.sweep"
    assert read_result(DATA / "v1_sweep.h5", 2).attributes["tangential.q_over_mu_p"] == 0.8


def test_files_honour_the_umask(tmp_path):
    result = solve(SMALL)
    old = os.umask(0o027)
    try:
        write_result(result, tmp_path / "r.h5")
    finally:
        os.umask(old)
    assert (os.stat(tmp_path / "r.h5").st_mode & 0o777) == 0o640


def test_low_level_attributes_are_the_ones_h5py_writes(tmp_path):
    """The writer's attribute path (:func:`rolling_cli.files.storage.set_attrs`, types derived once) gives
    every attribute the HDF5 type, shape and value that ``obj.attrs[name] = value`` gives, replaces an
    existing one, and leaves other kinds of value (bool, lists) to h5py."""
    from rolling_cli.files.storage import set_attrs

    values = {
        "text": "contact half-width",
        "unicode": "Young's modulus E [N/mm²], µ",
        "empty": "",
        "int": 7,
        "float": -2.5e-300,
        "int8": np.int8(1),
        "int32": np.int32(-3),
        "int64": np.int64(1 << 40),
        "uint": np.uint16(9),
        "float32": np.float32(0.1),
        "array_i1": np.array([0, 1, 2], dtype=np.int8),
        "array_i4": np.array([[1, 2], [3, 4]], dtype=np.int32),
        "array_f8": np.linspace(0.0, 1.0, 5),
        "bool": True,
        "list": [1.0, 2.0],
    }
    with h5py.File(tmp_path / "a.h5", "w") as handle:
        ours, theirs = handle.create_group("ours"), handle.create_group("theirs")
        set_attrs(ours, {"int": "replaced below"})
        set_attrs(ours, values)
        for name, value in values.items():
            theirs.attrs[name] = value
        assert list(ours.attrs) == list(theirs.attrs)
        for name in values:
            a = h5py.h5a.open(ours.id, name.encode())
            b = h5py.h5a.open(theirs.id, name.encode())
            assert a.get_type() == b.get_type(), name  # H5Tequal: class, size, sign, order
            assert _string_kind(a) == _string_kind(b) and a.shape == b.shape, name
            mine, reference = ours.attrs[name], theirs.attrs[name]
            assert type(mine) is type(reference) and np.array_equal(mine, reference), name


def _string_kind(attr) -> tuple | None:
    """Variable length and character set of a string attribute's type (H5Tequal ignores the set)."""
    kind = attr.get_type()
    if kind.get_class() != h5py.h5t.STRING:
        return None
    return kind.is_variable_str(), kind.get_cset()


def test_low_level_datasets_are_the_ones_h5py_creates(tmp_path):
    """The writer's contiguous numeric datasets (:func:`rolling_cli.files.storage.contiguous`) have the
    type, shape, layout, fill value and creation properties of ``create_dataset``'s."""
    from rolling_cli.files.storage import contiguous

    def properties(ds) -> tuple:
        dcpl = ds.id.get_create_plist()
        fill = np.zeros((), dtype=ds.dtype)
        dcpl.get_fill_value(fill)
        return (
            ds.dtype.str, ds.shape, ds.maxshape, ds.chunks, dcpl.get_layout(), dcpl.get_alloc_time(),
            dcpl.get_fill_time(), dcpl.fill_value_defined(), fill.tobytes(), dcpl.get_obj_track_times(),
            dcpl.get_attr_creation_order(), ds.id.get_type().get_order(), ds.id.get_type().get_size(),
        )  # fmt: skip

    kinds = [(np.dtype("f8"), np.nan, (1, 7)), (np.dtype("i8"), -1, (3,)), (np.dtype("i1"), np.int8(-1), (2, 5))]
    with h5py.File(tmp_path / "d.h5", "w", libver=("earliest", "v108")) as handle:
        for i, (dtype, fill, shape) in enumerate(kinds):
            for early, never in ((True, False), (True, True)):
                dcpls = []
                for _ in range(2):
                    dcpl = h5py.h5p.create(h5py.h5p.DATASET_CREATE)
                    if early:
                        dcpl.set_alloc_time(h5py.h5d.ALLOC_TIME_EARLY)
                    if never:
                        dcpl.set_fill_time(h5py.h5d.FILL_TIME_NEVER)
                    dcpls.append(dcpl)
                name = f"v{i}{int(never)}"
                ours = contiguous(handle, "ours_" + name, shape, dtype, fill, dcpls[0])
                theirs = handle.create_dataset(
                    "theirs_" + name, shape=shape, dtype=dtype, fillvalue=fill, dcpl=dcpls[1], track_times=False
                )
                assert ours.id.get_type() == theirs.id.get_type(), name
                assert properties(ours) == properties(theirs), name
                if not never:  # the fill, as written
                    assert np.array_equal(ours[()], theirs[()], equal_nan=True), name
