"""Graded and adaptive contact meshes: the mesh side of "accuracy on demand" (phase 1).

Pure functions on plain arrays and immutable grids, one job per module:

* :mod:`.kinks`: locate the contact edges and stick/slip boundaries of a
  solution to a fraction of a node spacing;
* :mod:`.grading`: element edges graded geometrically towards given points,
  with an edge on each;
* :mod:`.indicator`: an a-posteriori error indicator per element (the jumps of
  the discontinuous traction), a pure function of a solution and its grid;
* :mod:`.refine`: split the elements whose indicator exceeds a target;
  impose an element-length field on another grid;
* :mod:`.transfer`: prolongation of a solution onto another grid of the zone
  (a warm start);
* :mod:`.remesh`: one adaptive step, solution -> next grid;
* :mod:`.explicit`: solve a case on an explicit grid through
  :func:`rolling_cli.solve`.

The adaptive loop is then a thin layer (prototype: ``benchmarks/adaptive.py``)::

    result = solve(case)                                   # the case's uniform mesh
    while True:
        eta = indicator.element_indicator(grid, result.p_n, result.p_t, mu, p0)
        if eta.max() <= tolerance: break                   # (and a cap on refinements)
        positions, kinds = kinks.locate_kinks(result, grid)
        new = remesh.next_grid(grid, eta, positions, kinds, tolerance)
        start = transfer.transfer_tractions(grid, result.p_n, result.p_t, mu, new, edges)  # optional
        result = explicit.solve_on_grid(case, new, start)
        grid = new
"""
