"""Sensitivities of a converged solve by implicit differentiation (issue 24, item 1).

(Coulomb friction; a slip-speed friction law: :mod:`rolling_cli.solver.law_sensitivity`.)

At a converged solution the node states (separation, adhesion, slip and the
slip directions sigma) fix the reduced Newton system A z = b of
:mod:`rolling_cli.solver.reduced`. While they do not change, the solution is
z(theta) = A(theta)^-1 b(theta) for every parameter theta, so

    A dz/dtheta = -d(A z - b)/dtheta   (z held)

is one more linear solve per parameter with the final matrix (no Newton
iteration). A dense matrix is the Newton's last one when the converged state
has that step's node states (the usual case): its LU, kept by
:func:`rolling_cli.solver.reduced.newton_point`, solves every parameter's column
(:func:`rolling_cli.solver.kept.kept_system`: no assembly, no factorisation;
an overlap-controlled solve's matrix bordered by the load row and overlap column);
otherwise it is assembled and factorised once for all of them. At fixed node states
A and b are affine in each parameter (xi and P enter b, mu the slip tractions
p_t = -mu sigma p_n, Q the force row), so d(A z - b)/dtheta is the difference
of the system's residual at theta + h and at theta, exact for any h: h is
taken of the size of theta or larger, which keeps rounding at the level of
eps. The rows are assembled by :mod:`rolling_cli.solver.reduced` only.

What is held: creepage control differentiates Q(xi, mu, P), force control
xi(Q, mu, P), each in the control of the case (a Q/(mu P) or Q/P case is
differentiated with the force Q held, not the ratio). The other set follows
from the same linearisation by the implicit function theorem:
dxi/dQ = 1/(dQ/dxi), dxi/dmu = -(dQ/dmu)/(dQ/dxi), dxi/dP = -(dQ/dP)/(dQ/dxi)
(and back), so every case records all six; where dQ/dxi = 0 (full slip under
creepage control) the creepage derivatives are NaN. An overlap-controlled
solve is differentiated as the load-controlled problem at its own load (the
same solution; d/dP then holds P as the parameter instead of the overlap).
The derivatives in xi, Q and mu are those of the discrete problem on its own
grid; for the load see "Moving contact edges".

Ties: at a node exactly on a zone boundary the semismooth Jacobian is not
unique. The node states are the solver's (:func:`~rolling_cli.solver.formulation.node_sets`
at the converged state): contact where p_n + r_n delta_n < 0 strictly,
adhesion where |p_t - r_t s_t| < g strictly, so a node exactly on a boundary
counts as separated or slipping: the derivative is that of the branch on
which the node has left the contact or the adhesion zone (an element of the
B-subdifferential, one of the two one-sided derivatives).

Moving contact edges: the fixed-state derivative holds the contact set, whose
edges then move only by whole nodes. Where an edge of the contact is also an
end of the adhesion zone (Carter's leading edge), the edge's motion carries a
first-order part of dQ/dP that the fixed states miss: on Carter (200 elements)
dQ/dP at fixed states is 0.0163 against mu |xi| R*/(mu a) = 0.030 from the
closed form, and Q(P) on a fixed grid is a fine saw-tooth (slope 0.0163 between
node changes, mu while a new edge node slips) whose mean slope is 0.030.
Hence ``self_similar`` problems (a load on two half-spaces: the pipeline's grid,
zone and BEM blocks all scale with the Hertz a, so rollc's mapping is exactly
homogeneous, Q(l P, l^1/2 xi) = l Q(P, xi)) take the P-derivatives from that
homogeneity and the fixed-grid derivatives in xi, Q and mu:
P dF/dP = degree(F) F - (xi/2) dF/dxi under creepage control and
P dF/dP = degree(F) F - Q dF/dQ under force control, with degree 1 for Q and
1/2 for xi, a and p0 (a the recorded contact half-width, p0 = max|p_n|; dF/dxi
and dF/dQ at fixed states, a's by the argument below): so dQ/dP =
(Q - xi/2 dQ/dxi)/P, dxi/dP = (xi/2 - Q dxi/dQ)/P, and for similar bodies,
whose pressure does not move with xi or Q, da/dP = a/(2P), dp0/dP = p0/(2P).
These are the exact derivatives of ``rollc solve``'s result with respect to
the load (central differences of whole re-solves agree to 1e-7). Other
problems (layers, overlap control) take them at fixed states on their grid, and
the contact width by the active-set change argument: at fixed states the
outermost contact node k leaves the contact when its pressure reaches zero
(at P - p_k/(dp_k/dP)) and the next node j joins when its gap closes (at
P + delta_j/(-d delta_j/dP)); the edge advances one node spacing |x_j - x_k|
over that span of P, so da/dP = 1/2 sum over both ends |x_j - x_k| / span
(within 6 % of Hertz's a/(2P) on 100 half-plane elements, the error of one
node in the span). ``dp0_dP`` there is the derivative of max|p_n| at the node
that holds it.

Layer thickness (``[output] layer_derivative``, issue 24): the thickness b of a
layered body enters only the influence blocks (S_nn, S_nt, B_tt, B_tn), which
have no closed form in b. Their derivative is taken as a central difference
of the contact systems built at b + h and b - h on the same grid (h = 1e-4 b:
truncation ~h^2, the BEM's rounding over 2h ~1e-10 relative), so dQ/db (xi, mu,
P held) and dxi/db (Q, mu, P held) are the implicit derivatives of the solve
with a differenced influence (a derivative of the influence, not of the
solve: no re-solve). The grid is the case's: a re-planned case (whose zone
follows the measured contact width) would also move the grid.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, fields

import numpy as np

from . import kept, reduced
from .formulation import Problem, State, evaluate, node_sets, traction_scales
from .linalg import solve_dense
from .system import ContactSystem


@dataclass(frozen=True)
class Sensitivities:
    """Derivatives of a converged solve (module docstring).

    ``dQ_dxi`` [force/length], ``dQ_dmu`` [force/length], ``dQ_dP`` [-] (creepage
    xi, mu, P held in turn); ``dxi_dQ`` [1/(force/length)], ``dxi_dmu`` [-],
    ``dxi_dP`` [1/(force/length)] (Q, mu, P held in turn); ``da_dP``
    [length/(force/length)] the contact half-width's, ``dp0_dP`` [stress/(force/length)]
    the peak pressure's, with the case's tangential control held; ``dQ_db``, ``dxi_db`` the layer
    thickness's, ``dQ_dV`` [(force/length)/(length/time)], ``dxi_dV`` [time/length] the rolling
    speed's (a slip-speed friction law: :mod:`rolling_cli.solver.law_sensitivity`).
    """

    dQ_dxi: float
    dQ_dmu: float
    dQ_dP: float
    dxi_dQ: float
    dxi_dmu: float
    dxi_dP: float
    da_dP: float
    dp0_dP: float
    dQ_db: float = math.nan
    dxi_db: float = math.nan
    dQ_dV: float = math.nan
    dxi_dV: float = math.nan

    def as_dict(self) -> dict[str, float]:
        """The derivatives by name (the result quantities of the same names); the thickness and the
        rolling speed ones only when computed (not NaN)."""
        out = {f.name: float(getattr(self, f.name)) for f in fields(self)}
        if math.isnan(self.dQ_db) and math.isnan(self.dxi_db):
            del out["dQ_db"], out["dxi_db"]
        if math.isnan(self.dQ_dV) and math.isnan(self.dxi_dV):  # the rolling speed's: slip-speed laws only
            del out["dQ_dV"], out["dxi_dV"]
        return out


#: The derivatives of a case without them (no contact, frictionless tangential ones): all NaN.
UNDEFINED = Sensitivities(*([math.nan] * 8))


def sensitivities(
    system: ContactSystem,
    mu: float,
    state: State,
    force_control: bool,
    self_similar: bool = False,
    half_width: float | None = None,
    layer: tuple[ContactSystem, ContactSystem, float] | None = None,
) -> Sensitivities:
    """The derivatives of the converged ``state`` of ``system`` (module docstring).

    ``mu`` the friction coefficient, ``force_control`` whether the case prescribes
    the tangential force (else the creepage), ``self_similar`` whether rollc's
    mapping is homogeneous in the load (a load on two half-spaces; the
    P-derivatives then come from the homogeneity; ``half_width`` the contact half-width
    [length] when known, else measured here). ``layer``: (the contact system at b + h, at
    b - h, h [length]) of a layered body of thickness b on the same grid: the derivatives along b
    too (module docstring, "Layer thickness"). A frictionless case has only
    the normal derivatives (the tangential ones NaN). Raises
    ``numpy.linalg.LinAlgError`` when the final reduced matrix is singular.
    """
    w = system.weights
    load = system.load(state.p_n, state.p_t)  # P as normal.load prescribes it (a finite cylinder's: on its shaft)
    if not load > 0.0:
        reduced.release()
        return UNDEFINED
    q = float(w @ state.p_t)
    tangential = mu > 0.0
    # decoupled with the load-derivatives by homogeneity: the tangential stage alone (p_n held)
    staged = tangential and self_similar and system.S_nt is None
    mode = "tangential" if staged else ("coupled" if tangential else "normal")
    force = ("load", q) if tangential and force_control else None
    problem = Problem(system, mode, mu, load=load, force=force)
    ev = evaluate(problem, state, traction_scales(problem, state))
    sets = node_sets(problem, state, ev)
    base = kept.kept_system(problem, state, sets, ev)
    names = ([] if self_similar else ["P"]) + (["Q" if force else "xi", "mu"] if tangential else [])
    names += ["b"] if layer is not None and tangential else []
    tangents = _tangents(problem, state, sets, ev, base, names, layer)
    peak_node = int(np.argmin(state.p_n))
    if self_similar:  # homogeneity: P dF/dP = degree(F) F - (Q or xi/2) dF/d(Q or xi) (module docstring)
        tangent = tangents.get("Q" if force else "xi")
        weight = (q if force else 0.5 * state.creep) if tangent is not None else 0.0
        if half_width is None:
            lo, hi = system.extent(state.p_n < 0.0)
            half_width = 0.5 * (hi - lo)
        d_a = d_p0 = 0.0
        if tangent is not None and np.any(tangent.dp_n):  # the pressure moves with Q or xi (coupled)
            d_a = _edge_derivative(system, state, sets.contact, tangent)
            d_p0 = float(-tangent.dp_n[peak_node])
        da = (0.5 * half_width - weight * d_a) / load
        dp0 = (0.5 * float(-state.p_n[peak_node]) - weight * d_p0) / load
    else:
        da = _edge_derivative(system, state, sets.contact, tangents["P"])
        dp0 = float(-tangents["P"].dp_n[peak_node])
    if not tangential:
        nan = math.nan
        return Sensitivities(nan, nan, nan, nan, nan, nan, da, dp0)
    if force:
        dxi_dq, dxi_dmu = tangents["Q"].d_creep, tangents["mu"].d_creep
        dxi_dp = (0.5 * state.creep - q * dxi_dq) / load if self_similar else tangents["P"].d_creep
        return _thickness(_from_creep_derivatives(dxi_dq, dxi_dmu, dxi_dp, da, dp0), tangents.get("b"), True)
    dq_dxi, dq_dmu = tangents["xi"].d_force, tangents["mu"].d_force
    dq_dp = (q - 0.5 * state.creep * dq_dxi) / load if self_similar else tangents["P"].d_force
    return _thickness(_from_force_derivatives(dq_dxi, dq_dmu, dq_dp, da, dp0), tangents.get("b"), False)


def _tangents(problem: Problem, state: State, sets, ev, base: reduced.ReducedSystem, names: list[str], layer) -> dict:
    """The :class:`Tangent` of each parameter in ``names``: its column, all solved with one LU."""
    if not names:
        return {}
    columns = np.column_stack([
        _thickness_column(problem, state, sets, base, layer) if name == "b" else
        _column(problem, state, sets, ev, base, name)
        for name in names
    ])  # fmt: skip
    if base.factor is not None:  # the Newton's last LU (one getrs for every column)
        dz = base.factor.solve(columns).reshape(columns.shape)
    elif isinstance(base.matrix, np.ndarray):
        dz = _solve_blocks(problem, base, columns)
    else:
        dz = np.column_stack([reduced.solve_reduced(base, columns[:, k]) for k in range(len(names))])
    return {name: _tangent(problem, state, base, dz[:, k], name) for k, name in enumerate(names)}


def _thickness_column(problem: Problem, state: State, sets, base: reduced.ReducedSystem, layer) -> np.ndarray:
    """-d(A z - b)/d(layer thickness) at fixed z and node states: the elastic rows' change,
    r_n (dS_nn p_n + dS_nt p_t) on the contact rows and r_t (dB_tt p_t + dB_tn p_n) on the
    adhesion rows, each block's derivative the central difference of the systems at b +- h (the
    load and force rows do not hold the influence). NaN on operator (matrix-free) blocks."""
    plus, minus, h = layer
    system = problem.system
    out = np.zeros(base.rhs.size)
    if not isinstance(plus.S_nn, np.ndarray) or not isinstance(minus.S_nn, np.ndarray):
        return np.full(base.rhs.size, math.nan)

    def product(name: str, values: np.ndarray) -> np.ndarray:
        high, low = getattr(plus, name), getattr(minus, name)
        return np.zeros(system.size) if high is None or low is None else ((high - low) / (2.0 * h)) @ values

    nc = sets.contact.size if problem.normal else 0
    ns = sets.stick.size
    if problem.normal:
        out[:nc] = -system.penalty_n * (product("S_nn", state.p_n) + product("S_nt", state.p_t))[sets.contact]
    out[nc : nc + ns] = -system.penalty_t * (product("B_tt", state.p_t) + product("B_tn", state.p_n))[sets.stick]
    return out


def _thickness(found: Sensitivities, tangent: Tangent | None, force: bool) -> Sensitivities:
    """``found`` with the thickness derivatives of ``tangent`` (the other one by the implicit
    function theorem: dQ/db = -(dxi/db)/(dxi/dQ) at fixed xi, dxi/db = -(dQ/db)/(dQ/dxi) at fixed Q)."""
    if tangent is None:
        return found
    if force:
        return dataclasses.replace(found, dxi_db=tangent.d_creep, dQ_db=-tangent.d_creep * found.dQ_dxi)
    return dataclasses.replace(found, dQ_db=tangent.d_force, dxi_db=-tangent.d_force * found.dxi_dQ)


def _solve_blocks(problem: Problem, base: reduced.ReducedSystem, columns: np.ndarray) -> np.ndarray:
    """dZ with A dZ = columns for a dense A, one LU for every column. Without the normal-tangential
    coupling the normal rows do not involve the tangential unknowns: A is block lower triangular,
    and the normal block (contact nodes and overlap) is solved first, then the tangential one (the
    decoupled solver's two stages; two small LUs cost ~1/4 of the whole one's at Carter's sizes)."""
    matrix = base.matrix
    if not isinstance(matrix, np.ndarray):
        raise TypeError("a dense reduced matrix is needed")
    if problem.mode != "coupled" or problem.system.S_nt is not None or problem.system.load_t is not None:
        return solve_dense(matrix, columns).reshape(columns.shape)
    nc = base.sets.contact.size
    normal = np.r_[np.arange(nc), [] if base.col_overlap is None else [base.col_overlap]].astype(int)
    other = np.setdiff1d(np.arange(matrix.shape[0]), normal)
    out = np.empty_like(columns)
    out[normal] = solve_dense(matrix[np.ix_(normal, normal)], columns[normal]).reshape(normal.size, -1)
    rhs = columns[other] - matrix[np.ix_(other, normal)] @ out[normal]
    out[other] = solve_dense(matrix[np.ix_(other, other)], rhs).reshape(other.size, -1)
    return out


def _ratio(numerator: float, denominator: float) -> float:
    return numerator / denominator if denominator != 0.0 else math.nan


def _from_force_derivatives(dq_dxi: float, dq_dmu: float, dq_dp: float, da: float, dp0: float) -> Sensitivities:
    """Both sets from Q's derivatives (creepage control)."""
    inverse = _ratio(1.0, dq_dxi)
    return Sensitivities(
        dq_dxi, dq_dmu, dq_dp, inverse, -dq_dmu * inverse, -dq_dp * inverse, da, dp0
    )  # fmt: skip


def _from_creep_derivatives(dxi_dq: float, dxi_dmu: float, dxi_dp: float, da: float, dp0: float) -> Sensitivities:
    """Both sets from the creepage's derivatives (force control)."""
    inverse = _ratio(1.0, dxi_dq)
    return Sensitivities(inverse, -dxi_dmu * inverse, -dxi_dp * inverse, dxi_dq, dxi_dmu, dxi_dp, da, dp0)


def _step(problem: Problem, state: State, name: str) -> float:
    """The difference h of parameter ``name``: its own size or larger (module docstring)."""
    load = float(problem.load or 0.0)
    if name == "P":
        return load
    if name == "Q":
        return max(abs(problem.force[1]) if problem.force else 0.0, load)
    return max(abs(state.creep), 1.0)


def _column(problem, state, sets, ev, base: reduced.ReducedSystem, name: str) -> np.ndarray:
    """-d(A z - b)/d theta at fixed z and node states (module docstring). P, Q and xi move the
    right-hand side alone: the difference of two layouts, exact for any h; mu moves the slip
    tractions (:func:`~rolling_cli.solver.reduced.friction_rows`)."""
    if name == "mu":
        return -reduced.friction_rows(problem, base, state)
    h = _step(problem, state, name)
    moved_state = state
    if name == "P":
        moved = problem.held(load=float(problem.load or 0.0) + h)
    elif name == "Q":
        moved = problem.held(force=("load", (problem.force[1] if problem.force else 0.0) + h))
    else:
        moved, moved_state = problem, state.copy()
        moved_state.creep = state.creep + h
    return (reduced.layout(moved, moved_state, sets, ev).rhs - base.rhs) / h


@dataclass(frozen=True)
class Tangent:
    """The derivative of a converged state along one parameter theta: tractions ``dp_n``, ``dp_t``
    [stress/theta], ``d_overlap`` [length/theta], ``d_force`` dQ/dtheta, ``d_creep`` dxi/dtheta."""

    dp_n: np.ndarray
    dp_t: np.ndarray
    d_overlap: float
    d_force: float
    d_creep: float


def _tangent(problem: Problem, state: State, base: reduced.ReducedSystem, dz: np.ndarray, name: str) -> Tangent:
    """The :class:`Tangent` of the reduced solution's derivative ``dz`` along parameter ``name``."""
    system, sets = problem.system, base.sets
    nc = sets.contact.size if problem.normal else 0
    ns = sets.stick.size
    dp_n = np.zeros(system.size)
    dp_n[sets.contact[:nc]] = dz[:nc]
    dp_t = np.zeros(system.size)
    if problem.tangential:
        dp_t[sets.stick] = dz[nc : nc + ns]
        if base.coef is not None:  # slip nodes, coupled mode: p_t = coef p_n with coef = -mu sigma
            coef = base.coef[np.searchsorted(sets.contact, sets.slip)]
            dp_t[sets.slip] = coef * dp_n[sets.slip]
        if name == "mu":  # and p_t = -mu sigma p_n moves with mu itself
            dp_t[sets.slip] += -sets.sigma[sets.slip] * state.p_n[sets.slip]
    d_creep = float(dz[base.col_creep]) / system.penalty_t if base.col_creep is not None else float(name == "xi")
    d_overlap = float(dz[base.col_overlap]) / system.penalty_n if base.col_overlap is not None else 0.0
    return Tangent(dp_n, dp_t, d_overlap, float(system.weights @ dp_t), d_creep)


def _edge_derivative(system: ContactSystem, state: State, contact: np.ndarray, tangent: Tangent) -> float:
    """d a / d theta [length/theta] by the active-set change argument (module docstring), along the
    parameter of ``tangent``. At each end, with t the parameter's change: the outermost contact node
    k leaves at t_k = -p_k / dp_k, the next node j joins at t_j = -delta_j / d delta_j; between the
    two the edge moves by |x_j - x_k| (outwards when t_j > 0 > t_k, inwards when t_k > 0 > t_j,
    not at all when neither moves). NaN when an end of the contact is the end of the zone or the
    two predictions are inconsistent (both ahead or both behind)."""
    if contact.size == 0:
        return math.nan
    ends = ((contact[-1], contact[-1] + 1), (contact[0], contact[0] - 1))
    if not all(0 <= j < system.size for _, j in ends):
        return math.nan
    rows = np.array([j for _, j in ends])
    gap = _gap_rows(system, rows, state.p_n, state.p_t) - state.overlap + system.gap0[rows]
    d_gap = _gap_rows(system, rows, tangent.dp_n, tangent.dp_t) - tangent.d_overlap
    total = 0.0
    for row, (k, j) in enumerate(ends):
        gap_j, d_gap_j = gap[row], d_gap[row]
        leaves = -state.p_n[k] / tangent.dp_n[k] if tangent.dp_n[k] != 0.0 else math.inf
        joins = -gap_j / d_gap_j if d_gap_j != 0.0 else math.inf
        if math.isinf(leaves) and math.isinf(joins):
            continue  # this edge does not move
        if joins > 0.0 > leaves or leaves > 0.0 > joins:
            total += 0.5 * abs(system.x[j] - system.x[k]) / (joins - leaves)
        else:
            return math.nan
    return total


def _gap_rows(system: ContactSystem, rows: np.ndarray, p_n: np.ndarray, p_t: np.ndarray) -> np.ndarray:
    """(S_nn p_n + S_nt p_t)[rows] [length]: the rows' products on dense blocks, else whole products."""
    if isinstance(system.S_nn, np.ndarray):
        out = system.S_nn[rows] @ p_n
        if system.S_nt is not None:
            out = out + system.S_nt[rows] @ p_t
        return out
    return (system.gap(p_n, p_t, 0.0) - system.gap0)[rows]
