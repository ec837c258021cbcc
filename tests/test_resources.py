"""Resources before work (issue #15, item 6): the memory model against measured peaks,
and the clear refusal of what will not fit, before anything is allocated."""

import json
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

from helpers import case_dict, dissimilar, run_cli, write_case
from rolling_cli.case import load_case
from rolling_cli.errors import CaseError
from rolling_cli.influence import bem, halfplane
from rolling_cli.model.grid import ContactGrid
from rolling_cli.pipeline import machine, resources

CASES = Path(__file__).resolve().parents[1] / "cases"

# One solve in a fresh process: the peak of the traced numpy arrays (tracemalloc)
# and the growth of the peak resident set (ru_maxrss) over the imports' baseline.
_MEASURE = """
import json, resource, sys, tracemalloc
import scipy.linalg  # loaded lazily by the first dense solve: its modules' memory is no array of the solve
from rolling_cli.case import load_case
from rolling_cli.pipeline import solve
case = load_case(json.loads(sys.argv[1]))
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
tracemalloc.start()
solve(case, use_cache=False)
peak = tracemalloc.get_traced_memory()[1]
rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - base
print(json.dumps({"traced": peak, "rss": 1024 * rss}))
"""


def _tyred(elements: int) -> dict:
    data = tomllib.loads((CASES / "tyred_fig11_q41.toml").read_text())
    data["discretization"]["contact_elements"] = elements
    return data


MEASURED = {
    "half-plane, decoupled": case_dict(**{"discretization.contact_elements": 290}),
    "half-plane, coupled": dissimilar(**{"discretization.contact_elements": 260}),
    # the matrix-free path (uniform grids from halfplane.OPERATOR_NODES = 900 nodes): 3,000 nodes,
    # and 3,600 whose coarse grid level (900 nodes) is matrix-free too
    "half-plane matrix-free, decoupled": case_dict(**{"discretization.contact_elements": 1000}),
    "half-plane matrix-free, coupled": dissimilar(**{"discretization.contact_elements": 1200}),
    "BEM, two bodies": dissimilar(**{"discretization.contact_elements": 120, "discretization.influence": "bem"}),
    "BEM layer, pre-solve": _tyred(120),
}


def test_memory_model_against_measured_peaks():
    """Each case runs in its own process. The model (the estimate without its allocator
    margin) must match the traced peak within [0.8, 1.3]: at these sizes the arrays it
    leaves out (O(n) vectors, histories, small BEM index arrays) stay below 20 % of the
    peak, and it counts the Newton matrix at its largest (every contact node adhering;
    at most ~30 % above the measured size in the coupled cases). The estimate itself
    must bound the measured growth of the resident set."""
    procs = {
        name: subprocess.Popen([sys.executable, "-c", _MEASURE, json.dumps(data)], stdout=subprocess.PIPE, text=True)
        for name, data in MEASURED.items()
    }
    rows = []
    for name, proc in procs.items():
        out, _ = proc.communicate(timeout=600)
        assert proc.returncode == 0, name
        measured = json.loads(out)
        found = resources.estimate(load_case(MEASURED[name]))
        model = found.bytes / resources.ALLOCATOR_MARGIN
        rows.append((name, model / measured["traced"], found.bytes / max(measured["rss"], 1)))
        assert 0.8 <= model / measured["traced"] <= 1.3, (name, found, measured)
        assert measured["rss"] <= found.bytes, (name, found, measured)
    print("\n".join(f"{name}: model/traced {a:.2f}, estimate/RSS {b:.2f}" for name, a, b in rows))


@pytest.mark.parametrize(
    "zone_half_width,elements,half_width,depth,largest",
    [
        (1.5, 200, 150.0, 100.0, None),  # the default half-space block
        (0.3, 21, 7.0, 90.0, None),  # a narrow, deep block
        (1.5, 100, 2.5, 0.1, 0.1),  # the paper's layer, b/a = 0.1
        (2.0, 300, 2.0 + 10 * 0.03, 0.03, 0.03),  # a thinner layer
        (1.0, 40, 1.0 + 5 * 1.0, 1.0, 1.0),  # a layer thicker than the contact
    ],
)
def test_mesh_counts_match_the_mesh_generator(zone_half_width, elements, half_width, depth, largest):
    """The estimate counts BEM nodes and elements without building the mesh: exactly."""
    mesh = bem.body_mesh(ContactGrid(zone_half_width, elements, 2), half_width, depth, largest=largest)
    counted = resources.rectangle_size(zone_half_width, elements, half_width, depth, largest)
    assert counted == (mesh.size, mesh.elements)


def test_graded_count_matches_graded_edges():
    rng = np.random.default_rng(7)
    for _ in range(200):
        length, first = 10 ** rng.uniform(-2, 2, size=2)
        largest = first * 10 ** rng.uniform(-1, 3)
        edges = bem.mesh.graded_edges(0.0, length, first, 1.4, largest)
        count, last = resources.graded_count(length, first, 1.4, largest)
        assert count == edges.size - 1
        assert last == pytest.approx(edges[-1] - edges[-2], rel=1e-9)


def _limited(case_path, *args, limit_mb: int) -> subprocess.CompletedProcess:
    """``rollc`` in a process whose address space may grow only ``limit_mb`` beyond
    what it holds after its imports (a real ``ulimit -v``)."""
    code = f"""
import resource, sys
import scipy.optimize, rolling_cli.pipeline, rolling_cli.files.io_hdf5, rolling_cli.report.summary  # before the limit
from rolling_cli.cli import main
used = next(int(l.split()[1]) for l in open("/proc/self/status") if l.startswith("VmSize:")) * 1024
resource.setrlimit(resource.RLIMIT_AS, (used + {limit_mb} * 2**20, resource.getrlimit(resource.RLIMIT_AS)[1]))
sys.argv = ["rollc", *sys.argv[1:]]
main()
"""
    return subprocess.run(
        [sys.executable, "-c", code, *args, str(case_path)], capture_output=True, text=True, timeout=300
    )


def test_refusal_under_a_memory_limit(tmp_path):
    """Under ``ulimit -v`` (300 MB of headroom) a case far too large is refused at once with
    the one-line error (key, estimate, available memory); a small case still solves. (The
    issue's 60,000 nodes now fit, on the matrix-free path: 150,000 nodes do not.)"""
    big = write_case(tmp_path, case_dict(**{"discretization.contact_elements": 50000}), "big.toml")
    for command in (["check"], ["solve", "-o", str(tmp_path / "big.h5")]):
        run = _limited(big, *command, limit_mb=300)
        assert run.returncode == 2, run.stderr
        lines = run.stderr.strip().splitlines()
        assert len(lines) == 1 and "Traceback" not in run.stderr
        need = resources.format_bytes(resources.estimate(load_case(big)).bytes)
        assert f"big.toml: discretization.contact_elements = 50000: the solve needs about {need} of memory" in lines[0]
        assert "(150000 contact nodes; peak in Newton), more than the" in lines[0]
        available = float(lines[0].split("more than the ")[1].split(" MB")[0])
        assert 150 <= available <= 315  # the limit's headroom (300 MiB), less what the CLI used since
        assert "allowed: at most" in lines[0] and "contact elements on this machine" in lines[0]
    assert not (tmp_path / "big.h5").exists()
    fitting = int(lines[0].split("at most ")[1].split()[0])
    ok = write_case(tmp_path, case_dict(**{"discretization.contact_elements": min(fitting, 100)}), "ok.toml")
    run = _limited(ok, "-q", "solve", "-o", str(tmp_path / "ok.h5"), limit_mb=300)
    assert run.returncode == 0, run.stderr


def test_thin_layer_fails_before_the_pre_solve(monkeypatch):
    """The issue's layer of b = 1e-6 under the Fig. 11 load: 6 GB and 100 s of pre-solve,
    then the element rule refused it (since issue #14 the BEM halves by mirror symmetry:
    measured 498 MB of resident set and 38 s). Now it is refused before: by memory on a
    machine that lacks the estimate (naming the layer), else by the element rule with the
    contact estimated from the thin-layer limit (0.8-1.2 of the measured a, allowed 2x)."""
    data = _tyred(100)
    data["bodies"]["B"]["layer_thickness"] = 1e-6
    data["normal"] = {"load": 0.2}  # Fig. 11's load (its overlap, 0.0042, would exceed b)
    case = load_case(data)
    found = resources.estimate(case)
    assert found.stage == "the pre-solve that measures a" and found.key == "bodies.B.layer_thickness"
    assert 5e8 < found.bytes < 1e9  # measured: 498 MB of resident set
    monkeypatch.setattr(resources, "available_memory", lambda: 3e8)
    with pytest.raises(CaseError, match=r"^bodies.B.layer_thickness = 1e-06: the solve needs about \S+ MB"):
        resources.check_resources(case)
    monkeypatch.setattr(resources, "available_memory", lambda: 1e15)
    with pytest.raises(CaseError) as info:
        resources.check_resources(case)
    message = str(info.value)
    assert message.startswith("discretization.contact_elements = 100: too few for the layer of bodies.B")
    needed = int(message.split("allowed: >= ")[1].split()[0])
    # a = 3.5e-4 (thin-layer limit), halved: 2 zone (a/2) / (b/2) elements
    assert needed == pytest.approx(2 * 1.5 * 3.548e-4 / 2 / 0.5e-6, rel=1e-3)


def test_layer_rule_passes_the_shipped_cases():
    for name in ("tyred_fig11_q41", "tyred_compressible_q41"):
        resources.check_layer_elements(load_case(CASES / f"{name}.toml"))


def test_the_issue_cases_exceed_any_workstation(monkeypatch):
    """The estimates of issue #15's examples, against the sizes the solver would allocate."""
    case = load_case(case_dict(**{"discretization.contact_elements": 20000}))
    n = 60000
    # the matrix-free path (issue #14): O(n) arrays, the operators, the GMRES basis (101 vectors of
    # n / 1.5 unknowns) and the preconditioner's band (49 rows): 150 n / 1.5 doubles at least
    fast = resources.estimate(case)
    assert 8 * 150 * n / 1.5 <= fast.bytes <= 500e6
    # the dense path: S_nn, S_tt, B_tt and the decoupled Newton matrix with its LU copy, 8 bytes each
    monkeypatch.setattr(halfplane, "OPERATOR_NODES", 10**12)
    half_plane = resources.estimate(case)
    assert half_plane.bytes >= 8 * (3 * n**2 + 2 * (n / 1.5) ** 2)
    block = load_case(case_dict(**{"discretization.contact_elements": 2000, "discretization.influence": "bem"}))
    found = resources.estimate(block)
    # the BEM body's two mirror halves: each a system of N unknowns with n + 1 right-hand sides
    big_n = found.boundary_nodes
    assert big_n > 6000 and found.bytes >= 8 * (2 * big_n**2 + 2 * big_n * (found.nodes + 1))


def test_workers_multiply_the_need(monkeypatch):
    case = load_case(case_dict(**{"discretization.contact_elements": 100}))
    need = resources.estimate(case).bytes
    monkeypatch.setattr(resources, "available_memory", lambda: 2.5 * need)
    assert resources.check_resources(case, copies=2).bytes == need
    with pytest.raises(CaseError, match=r"of memory, \S+ MB for 3 workers \(300 contact nodes.*more than the"):
        resources.check_resources(case, copies=3)


def test_available_memory_is_bounded_by_the_kernel():
    found = resources.available_memory()
    meminfo = machine._read_kib("/proc/meminfo")
    if "MemAvailable" not in meminfo:
        pytest.skip("no /proc/meminfo here")
    assert 0 < found <= meminfo["MemAvailable"] * 1.05  # both read moments apart


def test_check_reports_the_estimate(tmp_path):
    result = run_cli("check", write_case(tmp_path, case_dict()))
    assert result.exit_code == 0
    derived = tomllib.loads(result.output)["derived"]
    found = resources.estimate(load_case(case_dict()))
    assert derived["memory_estimate"] == found.bytes and derived["work_estimate"] == found.flops
    assert derived["memory_available"] > 0 and "600 contact nodes" in derived["memory_note"]
