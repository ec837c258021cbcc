"""Cost of the bodies' surface displacements in the result (rolling_cli.influence.surface) and of
``rollc plot --deformed``, per shipped case: the time of the result's ``_surfaces`` step against
the whole in-process solve (the fastest of three), the bytes the four node variables add to the
result file, and the figure's time. Run from the repository root:
``OMP_NUM_THREADS=1 python benchmarks/bench_deformed.py``."""

from __future__ import annotations

import os
import sys
import tempfile
import time

import h5py

import rolling_cli
import rolling_cli.pipeline.assemble  # noqa: F401  (the module, shadowed by the function on the package)
from rolling_cli.report.plot_deformed import plot_deformed_file

CASES = ["carter", "dissimilar_q75", "dissimilar_q75_adaptive", "rubber_roller", "rubber_cover",
         "tyred_fig11_q05", "rubber_roller_finite"]  # fmt: skip


#: Solves per case; the fastest is reported.
REPEATS = 3


def main() -> None:
    assemble = sys.modules["rolling_cli.pipeline.assemble"]
    original = assemble._surfaces
    spent = [0.0]

    def timed(*args):
        t0 = time.perf_counter()
        out = original(*args)
        spent[0] += time.perf_counter() - t0
        return out

    assemble._surfaces = timed
    print(
        f"{'case':26s} {'nodes':>5s} {'solve s':>8s} {'surfaces ms':>11s} {'share':>6s} {'file +kB':>8s} {'plot s':>6s}"
    )
    with tempfile.TemporaryDirectory() as work:
        for name in CASES:
            runs = []
            for _ in range(REPEATS):  # the machine is shared: the fastest of a few solves
                spent[0] = 0.0
                t0 = time.perf_counter()
                result = rolling_cli.solve(rolling_cli.load_case(f"cases/{name}.toml"))
                runs.append((time.perf_counter() - t0, spent[0]))
            solve, spent[0] = min(r[0] for r in runs), min(r[1] for r in runs)
            path = os.path.join(work, f"{name}.h5")
            rolling_cli.write_result(result, path)
            with h5py.File(path, "r") as handle:
                extra = sum(handle[n].id.get_storage_size() for n in handle if n.startswith("surface_"))
            t0 = time.perf_counter()
            plot_deformed_file(path, os.path.join(work, f"{name}.png"))
            plot = time.perf_counter() - t0
            print(
                f"{name:26s} {result.x.size:5d} {solve:8.3f} {1e3 * spent[0]:11.2f} "
                f"{spent[0] / solve:6.1%} {extra / 1e3:8.1f} {plot:6.2f}"
            )


if __name__ == "__main__":
    main()
