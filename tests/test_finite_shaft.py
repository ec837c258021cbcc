"""What P and Q of a finite cylinder are on its shaft (issue 21): equilibrium of the whole boundary.

The BEM body is solved in full (every boundary value, no condensation) for given contact tractions;
the bore's tractions are what the rigid shaft exerts on the body. Equilibrium of the body: their
force is minus the contact tractions' resultant (which :func:`shaft_quantities` reports as
``shaft_load`` and ``shaft_tangential_load``), and their moment about the centre is R times the
arc sum Q = sum w p_t (the radial pressure has no moment about the centre): Q is the torque the
shaft transmits divided by R.
"""

from types import SimpleNamespace

import numpy as np
import pytest

from rolling_cli.influence.bem import assembly, condense, cylinder
from rolling_cli.influence.bem.elements import evaluate, gauss, map_points
from rolling_cli.influence.finite import shaft_quantities
from rolling_cli.model.grid import ContactGrid

RADIUS = 5.0


def _tractions(s, a):
    """Smooth contact tractions [stress] on arc lengths s: a pressure and an asymmetric tangential
    traction (C1 at |s| = a, so the quadratic elements carry them without a kink)."""
    bump = np.where(np.abs(s) < a, (1.0 - (s / a) ** 2) ** 2, 0.0)
    return -bump, 0.3 * bump * (1.0 + s / a)


def _integrals(mesh, elements, values):
    """Force (2,) and moment about the centre (0, -R) of the boundary tractions ``values`` (N, 2)
    over ``elements``, by 12-point Gauss on the curved elements (the shape functions interpolate)."""
    xg, wg = gauss(12)
    points, _, jac = map_points(mesh.geometry[elements], xg)
    shape = evaluate(assembly.lagrange_coefficients(mesh.local[elements]), np.broadcast_to(xg, jac.shape))
    t = np.einsum("egj,ejd->egd", shape, values[mesh.connectivity[elements]])  # (e, G, 2)
    weight = wg[None, :] * jac
    force = np.einsum("eg,egd->d", weight, t)
    arm = points - np.array([0.0, -RADIUS])
    moment = float(np.sum(weight * (arm[..., 0] * t[..., 1] - arm[..., 1] * t[..., 0])))
    return force, moment


@pytest.mark.parametrize("inner", [2.0, 4.0])
def test_shaft_reaction_balances_the_contact_tractions(inner):
    """Hollow roller (bore 2) and cover (core 4), R = 5, the load over a/R = 0.3. The bore's
    force equals minus the contact resultant within 1e-5 of it and its moment is R Q within 1e-4
    (the BEM satisfies equilibrium to its discretisation error, 40 contact elements and a coarse
    bore; measured 1e-6 and 1.3e-5); the contact pressure's moment about the centre vanishes and
    ``shaft_quantities`` (grid weights) gives the resultant of the interpolated tractions, both to
    rounding of the quadrature (1e-9 and 1e-8 allowed; measured 5e-11 and 2e-10)."""
    a = 0.3 * RADIUS
    grid = ContactGrid(1.2 * a, 40, 2)
    mesh = cylinder.annulus_mesh(grid, RADIUS, inner)
    shear, poisson = 10.0 / 2.6, 0.3
    H, G = assembly.assemble(mesh, shear, poisson)
    A, B = condense.boundary_system(mesh, H, G)
    theta = cylinder.contact_angles(mesh, RADIUS)
    p_n, p_t = _tractions(grid.x, a)
    nu = np.column_stack([np.sin(theta), np.cos(theta)])  # the block frame: body below, centre at (0, -R)
    tau = np.column_stack([np.cos(theta), -np.sin(theta)])
    known = np.zeros((mesh.size, 2))  # t on free nodes (zero off the contact), u = 0 on the bore
    known[mesh.contact] = p_n[:, None] * nu + p_t[:, None] * tau
    unknown = np.linalg.solve(A, B @ known.ravel()).reshape(mesh.size, 2)
    bore_t = np.where(mesh.fixed[:, None], unknown, 0.0)
    bore = np.flatnonzero(mesh.fixed[mesh.connectivity].all(axis=1))
    contact = np.arange(grid.elements)  # the contact elements come first
    f_contact, m_contact = _integrals(mesh, contact, known)
    f_bore, m_bore = _integrals(mesh, bore, bore_t)
    scale = np.abs(f_contact).max()
    assert np.abs(f_bore + f_contact).max() <= 1e-5 * scale
    q_arc = float(grid.weights @ p_t)
    assert abs(m_contact + RADIUS * q_arc) <= 1e-9 * RADIUS * abs(q_arc)  # the pressure has no moment
    assert abs(m_bore - RADIUS * q_arc) <= 1e-4 * RADIUS * abs(q_arc)  # the shaft's torque is R Q
    case = SimpleNamespace(
        bodies=SimpleNamespace(
            A=SimpleNamespace(shape="cylinder", radius=RADIUS), B=SimpleNamespace(shape="half-space")
        )
    )
    shaft = shaft_quantities(case, grid.x, grid.weights, p_n, p_t, 0.0, a)
    # the body-above frame of influence.finite: its load is the force towards the shaft, -F_y here
    assert abs(shaft["shaft_load"] + f_contact[1]) <= 1e-8 * scale
    assert abs(shaft["shaft_tangential_load"] - f_contact[0]) <= 1e-8 * scale
    assert abs(shaft["shaft_torque"] - RADIUS * q_arc) <= 1e-12 * RADIUS * abs(q_arc)
