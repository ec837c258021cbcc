"""Graded BEM contact grids (issue #13 item 1): the tyred case's adaptive levels, graded or uniform.

The tyred cylinder (cases/tyred_fig11_q41.toml, incompressible layer, b/a = 0.1, from its shipped
100 elements) in the adaptive mode at tolerances 0.05, 0.02 and 0.01: final contact elements, the
recorded estimate, the true maximum traction error / (mu p0) and the creepage error against two
references, the refinements and the in-process time (cache off, memo cleared: cold builds; fastest
of --repeats). References: the fine uniform BEM run of benchmarks/accuracy_cost.py (640 elements,
linearly interpolated: its own error next to the square-root kinks is several 1e-3 of mu p0), and
the adaptive graded BEM run at tolerance 1e-3 (interpolated with its element polynomials; its own
estimate bounds its error; at 3e-4 the estimate stalls near 1e-3). Both are written to --reference
/ --graded-reference and read back when they exist, so runs of two versions share them (the graded
one needs the graded BEM: compute it with the newer version first). Run from a checkout of each
version to compare ("before": uniform BEM levels; "after": graded levels):

    python benchmarks/graded_bem.py [--reference R.h5] [--graded-reference G.h5] [--tolerances ...]
"""

from __future__ import annotations

import argparse
import logging
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from accuracy_cost import Reference, adaptive_case, measure, run  # noqa: E402

import rolling_cli  # noqa: E402
from rolling_cli.case import load_case, with_overrides  # noqa: E402
from rolling_cli.files.io_hdf5 import read_result, write_result  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
REFERENCE_ELEMENTS = 640
GRADED_REFERENCE_TOLERANCE = 1e-3


def reference(path: Path, base):
    """The fine uniform BEM reference, read from ``path`` or solved and written there."""
    if path.exists():
        return read_result(path)
    r, _ = run(with_overrides(base, {"discretization.contact_elements": REFERENCE_ELEMENTS}))
    write_result(r, path)
    return read_result(path)


def graded_reference(path: Path, base):
    """The adaptive graded BEM reference, read from ``path`` or solved and written there."""
    if path.exists():
        return read_result(path)
    r, _ = run(adaptive_case(base, GRADED_REFERENCE_TOLERANCE, refinements=16))
    write_result(r, path)
    return read_result(path)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--reference", type=Path, default=Path("/tmp/tyred_fig11_q41_640.h5"))
    parser.add_argument("--graded-reference", type=Path, default=Path("/tmp/tyred_fig11_q41_graded.h5"))
    parser.add_argument("--tolerances", type=float, nargs="+", default=[0.05, 0.02, 0.01])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    logging.getLogger("rolling_cli").setLevel(logging.ERROR)
    print(f"rolling_cli from {Path(rolling_cli.__file__).parent}", flush=True)
    base = load_case(ROOT / "cases" / "tyred_fig11_q41.toml")
    ref = Reference(reference(args.reference, base))
    fine = graded_reference(args.graded_reference, base)
    graded = Reference(fine)
    print(
        f"graded reference: {fine.contact_elements} elements, estimate "
        f"{float(fine.attributes['adaptive_estimate']):.2e}, met {bool(fine.attributes['adaptive_met'])}"
    )
    print(
        "| tolerance | met | elements | smallest / b | refinements | estimate | max error (graded ref) "
        "| max error (uniform 640) | creepage error (graded ref) | seconds | method |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for tolerance in args.tolerances:
        timed = [run(adaptive_case(base, tolerance)) for _ in range(args.repeats)]
        r, seconds = timed[0][0], min(t for _, t in timed)
        m, g = measure(r, seconds, ref), measure(r, seconds, graded)
        attrs = r.attributes
        smallest = float(min(abs(b - a) for a, b in zip(r.element_edges[:-1], r.element_edges[1:], strict=True)))
        method = "graded" if str(attrs.get("adaptive_method", "")).startswith("graded") else "uniform"
        print(
            f"| {tolerance:g} | {'yes' if attrs.get('adaptive_met') else 'no'} | {r.contact_elements} | "
            f"{smallest / 0.1:.3g} | {attrs.get('adaptive_refinements')} | "
            f"{float(attrs.get('adaptive_estimate', math.nan)):.2e} | {g['max']:.2e} | {m['max']:.2e} | "
            f"{g['creep']:.1e} | "
            f"{seconds:.1f} | {method} |",
            flush=True,
        )
        if not attrs.get("adaptive_met"):
            print(f"  note: {attrs.get('adaptive_note')}", flush=True)


if __name__ == "__main__":
    main()
