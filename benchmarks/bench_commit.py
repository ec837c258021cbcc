"""Cost of a sweep file's commits (issue 25): 300 commits of 8 rows (1800 nodes each) into room for 4000.

Run in each checkout: ``PYTHONPATH=<checkout> OMP_NUM_THREADS=1 python benchmarks/bench_commit.py``.
Prints the median commit time, the rebuilds (commits over 0.1 s), the file size before and after
``close`` and the time of ``close`` (the trim; since issue 25 also the sort into sweep order).
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from helpers import case_dict, solve  # noqa: E402
from rolling_cli.files.rows import row_from_result  # noqa: E402
from rolling_cli.files.writer import ResultFile  # noqa: E402


def main() -> None:
    result = solve(case_dict(**{"discretization.contact_elements": 600}))
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "bench.h5")
        writer = ResultFile(path, {"format": "rolling_cli.result", "format_version": 2}, ("friction.mu",), total=4000)
        times = []
        for chunk in range(300):
            for i in range(8):
                writer.add(row_from_result(result, 8 * chunk + i, {"friction.mu": 0.1}, message="" if i else "text"))
            start = time.perf_counter()
            writer.commit()
            times.append(time.perf_counter() - start)
        before = os.path.getsize(path)
        start = time.perf_counter()
        writer.close()
        closing = time.perf_counter() - start
        print(
            f"nodes {result.x.size}: median commit {1e3 * np.median(times[1:]):.1f} ms, first {1e3 * times[0]:.0f} ms, "
            f"rebuilds {sum(t > 0.1 for t in times)}, {before / 1e6:.1f} MB before close, close {closing:.2f} s, "
            f"{os.path.getsize(path) / 1e6:.1f} MB after"
        )


if __name__ == "__main__":
    main()
