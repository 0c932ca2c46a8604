"""ccpp: complete coverage path planning for mobile robots on occupancy-grid maps.

The Python face of the ccpp Rust library (the same code as the ``ccpp`` command line)::

    import ccpp
    m = ccpp.load_map("maps/teb_maze.yaml")
    r = ccpp.run(m, planner="ba-star", radius=0.15)
    print(r.metrics["effective_coverage"])
    r.save("out")                      # the files of `ccpp run --out out`

* :func:`load_map`, :func:`run`, :func:`plan`, :func:`planners` -- runs and known-map plans
  (zones: ``area=``, ``keepout=``; path exports: ``waypoints()``, ``export()``,
  ``save(out, export=[...])``), validated and executed by the library's ``Scenario`` (errors
  raise :class:`CcppError` with the command line's message);
* :class:`Env` -- a step-by-step environment (rotate / translate / move-to actions, local scan,
  known map, newly swept area as reward) on the simulator's own physics and sensor;
* :mod:`ccpp.gym` -- a Gymnasium wrapper (``pip install 'ccpp-planner[gym]'``);
* :func:`sweep` -- many runs over a Dask cluster, as a pandas DataFrame with the columns of
  ``ccpp bench``'s ``results.csv`` (``pip install 'ccpp-planner[sweep]'``).
"""

from ._ccpp import (
    CcppError,
    Env,
    Map,
    PlanResult,
    RunResult,
    __version__,
    load_map,
    plan,
    planners,
    run,
)
from .sweeps import CSV_COLUMNS, expand_maps, sweep

__all__ = [
    "CSV_COLUMNS",
    "CcppError",
    "Env",
    "Map",
    "PlanResult",
    "RunResult",
    "__version__",
    "expand_maps",
    "load_map",
    "plan",
    "planners",
    "run",
    "sweep",
]
