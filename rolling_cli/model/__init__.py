"""Physical models beyond the elastic compliance: constitutive laws that the contact
solver evaluates node by node (for example friction that depends on the slip speed,
:mod:`rolling_cli.model.friction`). Each module is a set of pure, vectorised
functions or frozen dataclasses with their units in the docstrings; the solver
(:mod:`rolling_cli.solver`) imports them, never the other way round.
"""
