"""The full boundary solution (u and t on every boundary node) of a BEM body under contact tractions.

Built from the existing BEM code (:mod:`rolling_cli.influence.bem`): the body's
mesh as the influence model meshes it, H and G, the mixed boundary system
(bottom fixed, every other face traction-free except the contact nodes) and
one LU for all load cases. The stress machinery (:mod:`.bem`) only needs the
result (mesh, u, t), however it is obtained.

Note: the half-space block's truncation conditions are being revised (a
far field from the Flamant solution); when that lands, the block should take
its boundary solution from that code and only the layer keep this one.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from .. import materials
from ..influence import bem as bem_model
from ..influence.bem.assembly import assemble
from ..influence.bem.condense import boundary_system, factorise
from ..influence.bem.mesh import BoundaryMesh
from ..influence.build import bem_inputs


def body_mesh(case, the_plan, body) -> BoundaryMesh:
    """The boundary mesh the BEM influence model uses for ``body`` (a block or a layer) [length]."""
    inputs = bem_inputs(case, the_plan, body)
    largest = inputs["depth"] if inputs["kind"] == "layered" else None
    return bem_model.body_mesh(the_plan.grid, inputs["half_width"], inputs["depth"], largest=largest)


def solve(mesh: BoundaryMesh, young: float, poisson: float, contact: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Boundary displacements and tractions for contact tractions ``contact`` (R, n_c, 2) [stress].

    ``contact[r, i] = (t_x, t_y)`` at contact node i (increasing x) of load
    case r, in the mesh frame (body below y = 0: t_x the tangential traction
    on the body along +x, t_y = p_n). Every other free node is traction-free,
    fixed nodes have u = 0. Returns u [length] and t [stress], each (R, N, 2).
    """
    contact = np.asarray(contact, dtype=float)
    cases = contact.shape[0]
    H, G = assemble(mesh, materials.shear_modulus(young, poisson), poisson)
    A, B = boundary_system(mesh, H, G)
    known = np.zeros((cases, mesh.size, 2))  # u on fixed nodes (zero), t elsewhere
    known[:, mesh.contact] = contact
    rhs = B @ known.reshape(cases, -1).T
    unknown = scipy.linalg.lu_solve(factorise(A), rhs, check_finite=False).T.reshape(cases, mesh.size, 2)
    fixed = mesh.fixed[None, :, None]
    u = np.where(fixed, 0.0, unknown)
    t = np.where(fixed, unknown, known)
    return u, t
