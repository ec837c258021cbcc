"""rolling_cli: steady two-dimensional rolling contact of elastic cylinders.

The method is González & Abascal's: boundary element (or closed-form)
influence coefficients condensed onto the contact nodes, the contact laws as
projection equations (augmented Lagrangian), and the generalised Newton
method. Data flows one way, through plain arrays, and each stage has its
folder:

1. **case** (:mod:`rolling_cli.case`): a TOML file validated into frozen
   dataclasses; every error names the file, the dotted key, the value and what
   is allowed.
2. **plan** (:mod:`rolling_cli.pipeline.planning`): E*, R*, beta, the Hertz
   scale, the contact grid (:mod:`rolling_cli.model.grid`) and the effects the
   case needs (:mod:`rolling_cli.pipeline.effects`); the physical model's
   pieces (materials, slip operator, kernel integrals, validity) are in
   :mod:`rolling_cli.model`.
3. **influence** (:mod:`rolling_cli.influence`): the condensed compliance
   blocks S_nn, S_nt, S_tn, S_tt on the contact nodes, from the closed-form
   half-plane (:mod:`~rolling_cli.influence.halfplane`) or the BEM
   (:mod:`~rolling_cli.influence.bem`).
4. **contact system** (:mod:`rolling_cli.solver.system`): gap and slip as
   linear functions of the tractions, with the upwind slip operator
   (:mod:`rolling_cli.model.slip`).
5. **Newton** (:mod:`rolling_cli.solver`): the projection equations solved by
   the generalised Newton method, with load control and a watchdog line
   search; the mesh path over levels (:mod:`rolling_cli.pipeline.mesh_path`)
   and adaptive meshes (:mod:`rolling_cli.adapt`) drive it.
6. **result** (:mod:`rolling_cli.result`, assembled by
   :mod:`rolling_cli.pipeline.assemble`): every quantity declared once with
   its unit and long name (:mod:`rolling_cli.result.quantities`).
7. **files** (:mod:`rolling_cli.files`): one layout for results and sweeps
   (:mod:`~rolling_cli.files.layout`), written by appending rows
   (:mod:`~rolling_cli.files.writer`), read by :mod:`~rolling_cli.files.reader`
   (:func:`open_result`: an ``xarray.Dataset``), exported as tables
   (:mod:`~rolling_cli.files.export`); **report** (:mod:`rolling_cli.report`):
   the summary and the figures; **studies** (:mod:`rolling_cli.study`): sweeps
   and families of creep-force curves, serially, on local workers or on Dask.

Imports run down this list only (``tests/test_architecture.py``); the CLI
(:mod:`rolling_cli.cli`) is the only place that catches errors and sets up
logging.

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
