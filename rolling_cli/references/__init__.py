"""Closed-form reference solutions, one pure function module each.

* :mod:`.hertz`: Hertz line contact (plane strain).
* :mod:`.carter`: Carter's (1926) steady rolling of similar cylinders.
* :mod:`.carter_surface`: the surface stress sigma_xx of Carter's contact
  (the trailing-edge tension).
* :mod:`.flamant`: a line force on a half-plane (the BEM half-space's far field).
* :mod:`.approach`: the approach of a half-space under a Hertz pressure,
  measured from the point at depth d below the contact (the overlap's meaning).
* :mod:`.thin_layer`: the thin bonded layer limits (sanity bounds).
* :mod:`.annulus`: Michell's series for an annulus bonded to a rigid shaft (the finite cylinder).
"""
