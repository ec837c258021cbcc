"""rolling_cli: steady two-dimensional rolling contact of elastic cylinders.

The method is González & Abascal's: boundary element (or closed-form)
influence coefficients condensed onto the contact nodes, the contact laws as
projection equations (augmented Lagrangian), and the generalised Newton
method. Data flows one way, through plain arrays:

1. **case** (:mod:`rolling_cli.case`): a TOML file validated into frozen
   dataclasses; every error names the file, the dotted key, the value and what
   is allowed.
2. **plan** (:func:`rolling_cli.pipeline.plan`): E*, R*, beta, the Hertz scale,
   the contact grid (:mod:`rolling_cli.model.grid`) and the effects the case needs
   (:mod:`rolling_cli.pipeline.effects`).
3. **influence** (:mod:`rolling_cli.influence`): the condensed compliance
   blocks S_nn, S_nt, S_tn, S_tt on the contact nodes, from the closed-form
   half-plane (:mod:`~rolling_cli.influence.halfplane`) or the BEM
   (:mod:`~rolling_cli.influence.bem`); viscoelastic bodies
   (:mod:`rolling_cli.model.viscoelastic`) in steady rolling by the history
   kernels of :mod:`~rolling_cli.influence.viscoelastic`, their rolling
   resistance by :mod:`rolling_cli.model.resistance`.
4. **contact system** (:mod:`rolling_cli.solver.system`): gap and slip as linear
   functions of the tractions, with the upwind slip operator
   (:mod:`rolling_cli.model.slip`).
5. **Newton** (:mod:`rolling_cli.solver`): the projection equations solved by
   the generalised Newton method, with load control and a watchdog line search;
   then the derivatives of the converged solve by implicit differentiation
   (:mod:`rolling_cli.solver.sensitivity`: dQ/dxi, dQ/dmu, dQ/dP, ...).
6. **result** (:mod:`rolling_cli.result`), then **files and plots**: one
   layout for results and sweeps (:mod:`rolling_cli.files.layout`), written by
   appending rows (:mod:`rolling_cli.files.writer`), read by :mod:`rolling_cli.files.reader`
   (:func:`open_result`: an ``xarray.Dataset``), exported as tables
   (:mod:`rolling_cli.files.export`), plotted (:mod:`rolling_cli.report.plot`); sweeps
   (:mod:`rolling_cli.study.sweep`; families of creep-force curves:
   :mod:`rolling_cli.study.families`) run serially, on local workers or on Dask;
   creep-force tables (``rollc table``, built by :mod:`rolling_cli.study.tabulate`;
   :func:`rolling_cli.table.load` reads one as a numpy-only interpolant).

Python use::

    import rolling_cli
    case = rolling_cli.load_case("cases/carter.toml")
    result = rolling_cli.solve(case)
    print(result.tangential_load, result.creep)
    rolling_cli.write_result(result, "carter.h5")
    ds = rolling_cli.open_result("carter.h5")  # xarray.Dataset (dims case, node)
"""

from ._version import __version__

__all__ = ["__version__", "load_case", "solve", "write_result", "read_result", "open_result", "Result"]


def __getattr__(name):
    # Lazy imports keep `rollc --version` and the package import light.
    if name == "load_case":
        from .case import load_case

        return load_case
    if name == "solve":
        from .pipeline import solve

        return solve
    if name in ("write_result", "read_result"):
        from .files import io_hdf5

        return getattr(io_hdf5, name)
    if name == "open_result":
        from .files.dataset import open_result

        return open_result
    if name == "Result":
        from .result import Result

        return Result
    raise AttributeError(f"module 'rolling_cli' has no attribute {name!r}")
