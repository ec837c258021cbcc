"""The result file schema, relied on by other tools."""

import tomllib

import h5py
import numpy as np

from helpers import CARTER, case_dict, solve
from rolling_cli.io_hdf5 import read_result, write_result

ROOT_ATTRS = (
    "format",
    "format_version",
    "software_version",
    "created",
    "case",
    "converged",
    "iterations",
    "residual",
    "normal_load",
    "tangential_load",
    "creep",
    "overlap",
    "mu",
    "hertz_a",
    "hertz_p0",
    "beta_dundurs",
    "effects",
)


def test_schema_and_round_trip(tmp_path):
    result = solve(CARTER)
    path = tmp_path / "r.h5"
    write_result(result, path)
    with h5py.File(path) as f:
        for name in ROOT_ATTRS:
            assert name in f.attrs, name
        assert f.attrs["format"] == "rolling_cli.result" and f.attrs["format_version"] == 1
        assert f.attrs["created"].endswith("+00:00")
        case = tomllib.loads(f.attrs["case"])
        assert case["tangential"]["q_over_mu_p"] == 0.51 and case["solver"]["max_iterations"] == 100
        n = f["x"].shape[0]
        for name in ("x", "p_n", "p_t", "delta_n", "s_t", "state"):
            ds = f[name]
            assert ds.shape == (n,) and "units" in ds.attrs and "long_name" in ds.attrs
        assert f["state"].dtype == np.int8
        assert f["p_n"].attrs["units"] == "N/mm^2" and f["x"].attrs["units"] == "mm"
        assert set(np.unique(f["state"][()])) <= {0, 1, 2}
        assert "separation adhesion slip" == f["state"].attrs["flag_meanings"]
        assert f["convergence/residual"][-1] <= 1e-10
        assert "hertz_pressure" in f["reference"] and "carter_traction" in f["reference"]
        # Q is the weighted sum of the tangential traction, as documented
        assert np.isclose(f["weights"][()] @ f["p_t"][()], f.attrs["tangential_load"])
        assert np.isnan(f.attrs["overlap"])  # undefined for the half-plane model
    back = read_result(path)
    assert np.array_equal(back.p_t, result.p_t) and back.normal_load == result.normal_load
    assert back.history[-1]["residual"] == result.history[-1]["residual"]


def test_no_reference_for_dissimilar(tmp_path):
    data = case_dict(**{"bodies.A.young": 60260.0, "bodies.A.poisson": 0.31})
    result = solve(data)
    path = tmp_path / "d.h5"
    write_result(result, path)
    with h5py.File(path) as f:
        assert "reference" not in f
        assert f.attrs["beta_dundurs"] > 0.1
