"""Tyred-cylinder (layer) timings: mesh, assembly, factorisation, condensation,
Newton, for the paper's Fig. 11 case (rigid cylinder on an incompressible layer,
b/a = 0.1, Q/(mu P) = 0.41), 60 to 480 contact elements, cache off.

    python benchmarks/bench_layer.py [--repeat 3] [--elements 60,120,240,480]
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_bem import main  # noqa: E402

if __name__ == "__main__":
    main(
        Path(__file__).resolve().parents[1] / "cases" / "tyred_fig11_q41.toml",
        elements="60,120,240,480",
        name="bench_layer",
    )
