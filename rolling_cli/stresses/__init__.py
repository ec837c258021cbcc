"""Subsurface stresses, fatigue indicators and frictional power: what the tractions do to the bodies.

Computed only when a case has a ``[stresses]`` table (nothing here is imported
otherwise), from the converged surface tractions of the same discretisation:

* :mod:`.cauchy`: closed-form Cauchy integrals of piecewise-polynomial
  densities on a line (one logarithm per point and element edge, the rest
  matrix products), shared by both stress models;
* :mod:`.halfplane`: exact plane-strain fields of a half-plane under the
  contact grid's element tractions (Flamant integrated per element);
* :mod:`.surface`: a half-plane's surface stresses from a continuous traction
  with square-root contact edges (no log singularity at element ends);
* :mod:`.bem`: interior and boundary stresses of a BEM body from its boundary
  solution (mesh, u, t) by the Somigliana identity, integrated in closed form
  (the solution itself: :func:`rolling_cli.influence.build.boundary_solution`,
  the influence model's own half-space block or layer);
* :mod:`.curved`: the same identity on curved quadratic elements (Gauss
  quadrature by distance, product integration near the boundary), and
  :mod:`.cylinder`: a finite cylinder's field on its curvilinear grid (arc
  length, radial depth) from its annulus' boundary solution, and its bore;
* :mod:`.invariants`: sigma_yy, principal stresses, von Mises, Tresca, the
  orthogonal shear range;
* :mod:`.compute`: the fields of the requested bodies on their (x, z) grids;
* :mod:`.report`: :func:`attach` (one call after a solve), the indicator
  maxima, effects note, summary lines and sweep columns;
* :mod:`.power`: the frictional power density (in every result);
* :mod:`.io`: the ``stresses`` group of result files.

Frames: each body's stresses use x, the global rolling coordinate, and z >= 0,
the depth into that body; tau_xz(x, 0) = -p_t on body A and +p_t on body B
(p_t the traction on A). Compression is negative.
"""

from __future__ import annotations

__all__ = ["attach", "compute_stresses"]


def __getattr__(name):
    if name == "attach":
        from .report import attach

        return attach
    if name == "compute_stresses":
        from .compute import compute_stresses

        return compute_stresses
    raise AttributeError(f"module 'rolling_cli.stresses' has no attribute {name!r}")
