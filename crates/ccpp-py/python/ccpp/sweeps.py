"""Parameter sweeps (maps x planners x radii) fanned out over a Dask cluster.

Every run is one Dask task executing :func:`ccpp._ccpp.bench_run` -- the same run as one cell of
``ccpp bench`` (default options, default start) -- on a worker process; the result is a pandas
DataFrame with the columns of ``ccpp bench``'s ``results.csv`` (plus ``radius`` when several radii
are swept), in the bench's order (maps, then planners).

Point it at a cluster with ``client=`` (a ``distributed.Client``), ``scheduler="tcp://host:8786"``
or the environment variable ``CCPP_DASK_SCHEDULER``; without any, a local cluster with one worker
process per core is started for the call. Every worker needs the ``ccpp-planner`` package
installed and the map files at the same paths (a shared file system); so does ``out``.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Any, Iterable, Sequence

from . import _ccpp

if TYPE_CHECKING:
    import pandas

#: Columns of ``ccpp bench``'s ``results.csv``, in order.
CSV_COLUMNS: list[str] = [
    "map",
    "planner",
    "status",
    "error",
    "robot_radius_m",
    "tool_radius_m",
    "coverage_rate",
    "effective_coverage",
    "path_length_m",
    "path_ratio",
    "redundancy",
    "revisit_rate",
    "regions",
    "backtracks",
    "backtrack_length_m",
    "turns",
    "rotation_rad",
    "collisions",
    "wall_time_s",
    "dir",
]

_METRIC_COLUMNS = CSV_COLUMNS[4:19]


def expand_maps(items: Iterable[str | os.PathLike[str]] | str | os.PathLike[str]) -> list[Path]:
    """Map files as ``ccpp bench --maps`` takes them: a folder gives its ``*.yaml``/``*.yml``
    maps (or, when it has none, its PNG/PGM images), sorted; a file is taken as it is."""
    if isinstance(items, (str, os.PathLike)):
        items = [items]
    out: list[Path] = []
    for item in items:
        p = Path(item)
        if p.is_dir():
            files = sorted(p.iterdir())
            yamls = [f for f in files if f.suffix.lower() in (".yaml", ".yml")]
            out.extend(yamls or [f for f in files if f.suffix.lower() in (".png", ".pgm", ".pnm")])
        else:
            out.append(p)
    if not out:
        raise _ccpp.CcppError("no map found in " + ", ".join(str(i) for i in items))
    return out


def _run_cell(
    map_path: str,
    planner: str,
    radius: float,
    tool_radius: float | None,
    inflate: float | None,
    max_memory_mb: int | None,
    out_dir: str | None,
) -> dict[str, Any]:
    """One run on a worker: a row of the results."""
    from ccpp import _ccpp as native  # imported on the worker

    metrics, error = native.bench_run(
        map_path,
        planner,
        radius=radius,
        tool_radius=tool_radius,
        inflate=inflate,
        max_memory_mb=max_memory_mb,
        out=out_dir,
    )
    row: dict[str, Any] = {"map": Path(map_path).stem, "planner": planner}
    if metrics is None:
        row.update(status="error", error=error)
        row.update({c: None for c in _METRIC_COLUMNS})
    else:
        row.update(status="ok", error=None)
        row.update({c: metrics[c] for c in _METRIC_COLUMNS})
    row["dir"] = out_dir or ""
    return row


def sweep(
    maps: Iterable[str | os.PathLike[str]] | str | os.PathLike[str],
    planners: Sequence[str] | None = None,
    radii: Sequence[float] = (0.15,),
    *,
    tool_radius: float | None = None,
    inflate: float | None = None,
    max_memory_mb: int | None = None,
    out: str | os.PathLike[str] | None = None,
    client: Any = None,
    scheduler: str | None = None,
) -> "pandas.DataFrame":
    """Runs every planner on every map for every radius, one Dask task per run.

    ``maps`` are files or folders (as ``ccpp bench --maps``); ``planners`` default to all.
    With ``out``, each run's files are written to ``out/runs/MAP/PLANNER`` (with several radii,
    ``out/runs/r<RADIUS>/MAP/PLANNER``), as ``ccpp bench --out`` does. Failed runs are rows with
    ``status == "error"`` and the message in ``error``. Returns a pandas DataFrame with the
    columns :data:`CSV_COLUMNS` (plus ``radius`` when several radii are given).
    """
    import pandas as pd
    from distributed import Client

    known = [p["name"] for p in _ccpp.planners()]
    names = list(planners) if planners else known
    for p in names:
        if p not in known:
            raise _ccpp.CcppError(f'unknown planner "{p}"; run `ccpp planners` for the list')
    radii = list(radii)
    if not radii:
        raise _ccpp.CcppError("radii is empty")
    paths = expand_maps(maps)
    tasks = []
    for r in radii:
        for m in paths:
            for p in names:
                d = None
                if out is not None:
                    base = Path(out) / "runs"
                    if len(radii) > 1:
                        base = base / f"r{r}"
                    d = str(base / m.stem / p)
                tasks.append((str(m), p, float(r), tool_radius, inflate, max_memory_mb, d))

    own = None
    if client is None:
        address = scheduler or os.environ.get("CCPP_DASK_SCHEDULER")
        own = Client(address) if address else Client(processes=True)
        client = own
    try:
        futures = [client.submit(_run_cell, *t, pure=False) for t in tasks]
        rows = client.gather(futures)
    finally:
        if own is not None:
            own.close()
    df = pd.DataFrame(rows, columns=CSV_COLUMNS)
    if len(radii) > 1:
        df.insert(2, "radius", [t[2] for t in tasks])
    return df
