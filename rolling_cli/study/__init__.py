"""Studies of many cases: sweep specifications, warm-started paths, chunks, families of
creep-force curves, local and Dask workers. May import everything below the CLI.
"""
