"""The resource estimate (rolling_cli.pipeline.resources) against measured peaks and times.

Each case is solved once, cold (no influence cache), in its own process; the
table gives the estimated peak memory and the measured peak of the traced numpy
arrays (tracemalloc) and of the resident set (ru_maxrss over the imports'
baseline), the estimated work and the wall time, and the work rate they imply.

    python benchmarks/bench_resources.py [--quick]
"""

from __future__ import annotations

import json
import subprocess
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from helpers import case_dict, dissimilar  # noqa: E402
from rolling_cli.case import load_case  # noqa: E402
from rolling_cli.pipeline import resources  # noqa: E402

_MEASURE = """
import json, resource, sys, time, tracemalloc
from rolling_cli.case import load_case
from rolling_cli.pipeline import solve
case = load_case(json.loads(sys.argv[1]))
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
if sys.argv[2] == "traced":
    tracemalloc.start()
start = time.perf_counter()
solve(case, use_cache=False)
seconds = time.perf_counter() - start
peak = tracemalloc.get_traced_memory()[1] if sys.argv[2] == "traced" else 0
rss = 1024 * (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - base)
print(json.dumps({"traced": peak, "rss": rss, "seconds": seconds}))
"""


def _tyred(elements: int) -> dict:
    data = tomllib.loads((ROOT / "cases" / "tyred_fig11_q41.toml").read_text())
    data["discretization"]["contact_elements"] = elements
    return data


def cases(quick: bool) -> list[tuple[str, dict]]:
    hp = (200, 800) if quick else (200, 400, 800, 1600)
    hpc = (200, 600) if quick else (200, 400, 800, 1200)
    bem = (100, 300) if quick else (100, 200, 400, 600)
    layer = (100, 200) if quick else (100, 200, 300)
    out = [(f"half-plane Carter, {n} el.", case_dict(**{"discretization.contact_elements": n})) for n in hp]
    out += [(f"half-plane dissimilar, {n} el.", dissimilar(**{"discretization.contact_elements": n})) for n in hpc]
    out += [
        (
            f"BEM dissimilar, {n} el.",
            dissimilar(**{"discretization.contact_elements": n, "discretization.influence": "bem"}),
        )
        for n in bem
    ]
    out += [(f"BEM layer (Fig. 11), {n} el.", _tyred(n)) for n in layer]
    return out


def measure(data: dict, mode: str) -> dict:
    run = subprocess.run(
        [sys.executable, "-c", _MEASURE, json.dumps(data), mode], capture_output=True, text=True, check=True
    )
    return json.loads(run.stdout)


def main() -> None:
    quick = "--quick" in sys.argv
    print("| case | estimate | traced peak | RSS peak | estimate / RSS | work [flop] | time [s] | flop/s |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for name, data in cases(quick):
        found = resources.estimate(load_case(data))
        traced = measure(data, "traced")
        plain = measure(data, "rss")  # without tracemalloc's overhead: the time and the RSS
        print(
            f"| {name} | {resources.format_bytes(found.bytes)} | {resources.format_bytes(traced['traced'])} | "
            f"{resources.format_bytes(plain['rss'])} | {found.bytes / max(plain['rss'], 1):.2f} | "
            f"{found.flops:.2e} | {plain['seconds']:.2f} | {found.flops / plain['seconds']:.1e} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
