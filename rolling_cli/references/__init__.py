"""Closed-form reference solutions, one pure function module each.

* :mod:`.hertz`: Hertz line contact (plane strain).
* :mod:`.carter`: Carter's (1926) steady rolling of similar cylinders.
* :mod:`.approach`: the 2D approach of a cylinder into a block of finite depth,
  used to estimate the contact half-width when only the overlap is given.
* :mod:`.thin_layer`: the thin bonded layer limits (sanity bounds).
"""
