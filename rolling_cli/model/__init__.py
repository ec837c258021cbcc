"""Material and body models beyond the linear elastic solid.

Each module describes one kind of body that a case file may name under
``[bodies.X] kind``: its material constants, their conversion into what the
influence models need, and the checks on them. The influence kernels that use
them live in :mod:`rolling_cli.influence`; this package holds only the
constitutive side (:mod:`~rolling_cli.model.viscoelastic`: the standard linear
solid and Prony series in steady rolling).
"""
