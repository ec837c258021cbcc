import os
import sys
from pathlib import Path

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")
sys.path.insert(0, str(Path(__file__).parent))

if os.environ.get("PYTEST_XDIST_WORKER"):  # one test process per core (pytest-xdist): one BLAS thread each
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=1, user_api="blas")  # (two workers of two spinning threads on two cores waste CPU)


@pytest.fixture(autouse=True)
def _numpy_errors_raise():
    """numpy floating-point warnings are errors in the tests (plus pytest's filterwarnings = error)."""
    with np.errstate(divide="raise", over="raise", invalid="raise", under="ignore"):
        yield


@pytest.fixture(autouse=True)
def _isolated_cache(tmp_path_factory, monkeypatch):
    """Each test session writes influence caches under its own temporary directory."""
    monkeypatch.setenv("ROLLC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))
