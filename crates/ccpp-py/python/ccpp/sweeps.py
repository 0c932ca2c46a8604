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

import contextlib
import decimal
import importlib
import math
import numbers
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any, Iterable, Iterator, SupportsFloat

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
    "warnings",
]

#: Joins a run's warnings in its ``warnings`` field, as in ``results.csv`` (the same constant).
WARNINGS_SEPARATOR: str = _ccpp.WARNINGS_SEPARATOR

_METRIC_COLUMNS = CSV_COLUMNS[4:19]


def expand_maps(items: Iterable[str | os.PathLike[str]] | str | os.PathLike[str]) -> list[Path]:
    """Map files as ``ccpp bench --maps`` takes them (the same Rust function expands them): a
    folder gives its ``*.yaml``/``*.yml`` maps (or, when it has none, its PNG/PGM images),
    sorted; a file is taken as it is. A name that is neither, a folder without maps, or a map
    whose name is not UTF-8 is refused, as ``ccpp bench`` refuses it, before any run."""
    if isinstance(items, (bytes, bytearray)):
        # Iterated, a bytes path was its byte values ("expected str, bytes or os.PathLike
        # object, not int"); no path argument of ccpp takes bytes.
        raise _ccpp.CcppError(f"maps must be paths (str or os.PathLike), got {items!r}")
    if isinstance(items, (str, os.PathLike)):
        items = [items]
    return [Path(p) for p in _ccpp.expand_maps(list(items))]


def _map_names(paths: list[Path]) -> list[tuple[Path, str]]:
    """As ``ccpp bench`` names its maps (the same Rust function names them): a file named twice
    is run once, and every map gets a distinct name for its rows and run folders -- the file
    stem, or ``<folder>-<stem>`` when maps in different folders share a stem (then ``-2``,
    ``-3``, ... if that still repeats); a stem of dots is ``map``, ``summary`` is
    ``summary-map``."""
    return [(paths[i], name) for i, name in _ccpp.name_maps(paths)]


def _extra(module: str) -> Any:
    """Imports ``module``, a dependency of the ``[sweep]`` extra, saying how to install it when
    it is missing (a bare ``ModuleNotFoundError: pandas`` named no fix)."""
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as e:
        raise ModuleNotFoundError(
            f"ccpp.sweep needs {module}: install the sweep extra, pip install 'ccpp-planner[sweep]'"
            f" (or pip install './crates/ccpp-py[sweep]' from a clone)",
            name=e.name,
        ) from e


def _is_number(v: object) -> bool:
    """A real number as ``ccpp.run`` takes one for a radius: a ``numbers.Real`` (numpy's
    scalars too) or a ``decimal.Decimal`` (which ``run`` took and a sweep tried to iterate),
    not a bool; a 0-d numpy array of numbers too, as ``run`` takes it (a sweep refused
    ``np.array(0.2)``)."""
    if getattr(v, "ndim", None) == 0:
        return getattr(getattr(v, "dtype", None), "kind", None) in ("i", "u", "f")
    return not isinstance(v, bool) and isinstance(v, (numbers.Real, decimal.Decimal))


def _check_out(out: str | os.PathLike[str]) -> None:
    """``out`` is absent or a folder holding only a sweep's runs (``runs/``, the folder lock),
    so that the runs are never mixed with a user's own files. A folder with a bench's summary
    (``results.csv``, ``results.md``, ``plots/``) is refused too: a sweep writes no summary, and
    its runs would replace run folders that summary describes (``ccpp bench`` removes an
    earlier summary before its runs; a sweep left it, telling another radius's figures)."""
    p = Path(out)
    if not p.exists() and not p.is_symlink():
        return
    if p.is_symlink() or not p.is_dir():
        raise _ccpp.CcppError(f"output folder {p} exists and is not a plain folder")
    for e in sorted(p.iterdir()):
        if e.name in ("results.csv", "results.md", "plots", "results.csv.tmp", "results.md.tmp"):
            raise _ccpp.CcppError(
                f"output folder {p} holds {e.name}, the summary of an earlier ccpp bench, which a "
                "sweep does not rewrite and its runs would contradict; choose a new folder or "
                "remove results.csv, results.md and plots/ (and a results.csv.tmp or "
                "results.md.tmp left by a stopped bench) first"
            )
        if e.name == "runs":
            known = e.is_dir() and not e.is_symlink()
        elif e.name == _ccpp.STAMP_FILE:
            # ccpp's stamp: a bench's or sweep's folder holds it.
            known = e.is_file() and not e.is_symlink()
        elif e.name == _ccpp.LOCK_FILE:
            # A bench's or sweep's lock: held by a live one (refused when taken), or left by
            # a killed one (taken over).
            known = e.is_file() and not e.is_symlink()
        else:
            known = False
        if not known:
            raise _ccpp.CcppError(
                f"output folder {p} holds {e.name}, which a sweep or ccpp bench did not write; "
                "a sweep writes its runs there, so choose a new folder or one a sweep wrote"
            )


@contextlib.contextmanager
def _folder_lock(out: str | os.PathLike[str]) -> Iterator[None]:
    """Holds ``out``'s bench lock while a sweep writes there: the lock ``ccpp bench`` takes (one
    implementation, in the native module: the same file and operating-system lock), so a sweep
    and a bench, or two sweeps, never write one folder at once. A lock left by a killed process
    is taken over; one held is refused naming its process. The folder is made if missing, and
    removed again when the sweep wrote nothing into it (a sweep whose cluster could not be
    reached, ``scheduler="synchronous"``, left an empty folder behind)."""
    folder = Path(out)
    made = not folder.exists()
    folder.mkdir(parents=True, exist_ok=True)
    lock = _ccpp.FolderLock(folder)
    stamp = folder / _ccpp.STAMP_FILE
    had_stamp = stamp.is_file()
    done = False
    try:
        # The folder is ccpp's, as a bench's is (`ccpp bench` refuses a folder holding files
        # without ccpp's stamp); a sweep that fails takes back a stamp it wrote, so a folder
        # that was there stays with what it held.
        stamp.write_text(_ccpp.STAMP_TEXT)
        yield
        done = True
    finally:
        lock.release()
        if not done and not had_stamp:
            with contextlib.suppress(OSError):
                stamp.unlink()
        if made:
            with contextlib.suppress(OSError):
                # Only a folder holding nothing but the stamp goes (rmdir refuses any other).
                if [e.name for e in folder.iterdir()] == [_ccpp.STAMP_FILE]:
                    stamp.unlink()
                folder.rmdir()


def _once(items: Iterable[Any]) -> list[Any]:
    """The items in order, each once (as ``ccpp bench`` runs a planner named twice once)."""
    out: list[Any] = []
    for x in items:
        if x not in out:
            out.append(x)
    return out


def _run_cell(
    map_path: str,
    map_name: str,
    planner: str,
    radius: float,
    tool_radius: float | None,
    inflate: float | None,
    max_memory_mb: int | None,
    out_dir: str | None,
    shown_dir: str | None,
) -> dict[str, Any]:
    """One run on a worker: a row of the results (``out_dir`` absolute, ``shown_dir`` as the
    row names it)."""
    from ccpp import _ccpp as native  # imported on the worker

    metrics, error, warnings = native.bench_run(
        map_path,
        planner,
        radius=radius,
        tool_radius=tool_radius,
        inflate=inflate,
        max_memory_mb=max_memory_mb,
        out=out_dir,
        name=map_name,
    )
    row: dict[str, Any] = {"map": map_name, "planner": planner}
    if metrics is None:
        row.update(status="error", error=error)
        row.update({c: None for c in _METRIC_COLUMNS})
    else:
        # A run stopped early (`stalled`, `max_steps`) says so instead of `ok`, as in
        # `ccpp bench`'s results.csv.
        row.update(status=metrics.get("stop_reason") or "ok", error=None)
        row.update({c: metrics[c] for c in _METRIC_COLUMNS})
    # A failed run leaves no folder (as `ccpp bench`'s results.csv).
    row["dir"] = (shown_dir or "") if metrics is not None else ""
    # The warnings `ccpp run` prints (wide or stranded tiles, a boxed-in random bounce, ...),
    # None when there are none (an empty field of results.csv).
    row["warnings"] = WARNINGS_SEPARATOR.join(warnings) if warnings else None
    return row


def sweep(
    maps: Iterable[str | os.PathLike[str]] | str | os.PathLike[str],
    planners: Iterable[str] | str | None = None,
    radii: Iterable[SupportsFloat] | SupportsFloat | None = (0.15,),
    *,
    tool_radius: float | None = None,
    inflate: float | None = None,
    max_memory_mb: int | None = None,
    out: str | os.PathLike[str] | None = None,
    client: Any = None,
    scheduler: str | None = None,
) -> "pandas.DataFrame":
    """Runs every planner on every map for every radius, one Dask task per run.

    ``maps`` are files or folders (as ``ccpp bench --maps``; a map named twice runs once, maps
    sharing a file stem are told apart as ``<folder>-<stem>``; a missing one is refused before
    any run); ``planners`` default to all (a planner named twice runs once; one name as a string
    is that planner); ``radii`` (one number, or several) are checked (with ``tool_radius``)
    before any task starts, and a radius given twice runs once. With ``out``, each run's files
    are written to ``out/runs/MAP/PLANNER`` (with several radii, ``out/runs/r<RADIUS>/MAP/PLANNER``),
    as ``ccpp bench --out`` does (the same files but the bench's own ``bench-key.txt`` and
    ``warnings.txt``: a sweep's warnings are its ``warnings`` column), and ``out`` must be absent or hold only a sweep's runs (a
    folder with a bench's summary is refused: a sweep writes none).
    ``None`` for any keyword is its default. A run the simulator stopped early has that reason
    (``stalled``, ``max_steps``) as its ``status``. The cluster is ``client`` or ``scheduler`` (not both). Failed
    runs are rows with ``status == "error"`` and the message in ``error``. Returns a pandas
    DataFrame with the columns :data:`CSV_COLUMNS` (plus ``radius`` when several radii are
    given). ``max_memory_mb`` and ``inflate`` are checked before the cluster starts, too.

    Ctrl-C (or a failure) cancels the runs not yet gathered before the sweep lets ``out`` go;
    with a ``client`` of your own, runs already going on its workers cannot be stopped and may
    still write their folders after ``sweep`` has returned.

    In a script, call it under ``if __name__ == "__main__":`` when it starts a local cluster
    (no ``client`` and no ``scheduler``, or a ``LocalCluster``): Dask's worker processes import
    the script again.
    """
    if client is not None and scheduler is not None:
        # One of them would be ignored.
        raise _ccpp.CcppError("client and scheduler both name the cluster to use; give one of them")
    if client is not None and not (callable(getattr(client, "submit", None)) and callable(getattr(client, "gather", None))):
        # Found only when the tasks were submitted, as a bare AttributeError (kwargs pass).
        raise _ccpp.CcppError(f"client must be a distributed.Client, got {client!r}")
    known = [p["name"] for p in _ccpp.planners()]
    if isinstance(planners, str):
        # One planner, not its letters.
        planners = [planners]
    elif isinstance(planners, (bytes, bytearray)):
        # Iterated, b"bcd" was its byte values ('unknown planner "98"').
        raise _ccpp.CcppError(f"planners must be names (str), got {planners!r}")
    if planners is not None:
        # Any iterable (a generator has no len()); spaces around a name are dropped, as
        # `ccpp.run(planner=" bsa")` and `ccpp bench --planners "bsa, bcd"` drop them.
        planners = [p.strip() if isinstance(p, str) else p for p in planners]
    if planners is not None and len(planners) == 0:
        raise _ccpp.CcppError("planners is empty (leave it out, or None, for every planner)")
    names = _once(planners) if planners is not None else known
    for p in names:
        if p not in known:
            raise _ccpp.CcppError(f'unknown planner "{p}"; run `ccpp planners` for the list')
    if radii is None:
        radii = (0.15,)
    elif isinstance(radii, (str, bytes)):
        # Iterated, "0.2" was its characters ("got '0'").
        raise _ccpp.CcppError(f"radii must be numbers (metres), got {radii!r}")
    elif _is_number(radii):
        radii = (radii,)
    try:
        # Read once: a generator checked below and then converted was empty by then
        # ("radii is empty" for `(r for r in [0.2])`).
        radii = list(radii)
    except TypeError:
        raise _ccpp.CcppError(f"radii must be a number or numbers (metres), got {radii!r}") from None
    for r in radii:
        # `float()` took True as 1.0 m and "0.2" as 0.2: a radius is a number.
        if not _is_number(r):
            raise _ccpp.CcppError(f"radii must be numbers (metres), got {r!r}")
    radii = _once(float(r) for r in radii)
    if not radii:
        raise _ccpp.CcppError("radii is empty")
    for r in radii:
        _ccpp.check_robot(r, tool_radius)
    # Checked here, before the cluster starts: in the tasks a bad value raised a bare
    # OverflowError or TypeError from a worker, after other tasks had written their folders.
    if max_memory_mb is not None and (
        isinstance(max_memory_mb, bool)
        or not isinstance(max_memory_mb, numbers.Integral)
        or max_memory_mb < 1
        or max_memory_mb > 2**40  # the library's limit (1 EiB), as `ccpp bench --max-memory`
    ):
        raise _ccpp.CcppError(f"max_memory_mb must be a whole number of MB from 1 to {2**40}, got {max_memory_mb!r}")
    if inflate is not None and (
        isinstance(inflate, bool)
        or not isinstance(inflate, numbers.Real)
        or not math.isfinite(inflate)
        or inflate < 0
    ):
        raise _ccpp.CcppError(f"inflate must be a finite number of metres >= 0, got {inflate!r}")
    maps_named = _map_names(expand_maps(maps))
    if out is not None:
        _check_out(out)
    # The extras, after the arguments (a wrong argument is told the same with or without
    # them) and before any run (a sweep without pandas ran every task and then failed).
    pd = _extra("pandas")
    if client is None:
        _extra("distributed")
    tasks = []
    # The workers get absolute paths, made here: a worker of a cluster started in another
    # folder read relative map paths, and wrote relative `out` folders, in its own folder
    # (the caller's `out`, checked and locked, stayed empty while every row said ok).
    for r in radii:
        for m, map_name in maps_named:
            for p in names:
                d = None
                if out is not None:
                    base = Path(out) / "runs"
                    if len(radii) > 1:
                        base = base / f"r{r}"
                    d = str(base / map_name / p)
                tasks.append(
                    (
                        _from_here(m),
                        map_name,
                        p,
                        r,
                        tool_radius,
                        inflate,
                        max_memory_mb,
                        None if d is None else _from_here(d),
                        d,
                    )
                )

    with _folder_lock(out) if out is not None else contextlib.nullcontext():
        if out is not None:
            # Again under the lock: a bench may have finished there since the first check.
            _check_out(out)
        rows = _gather(tasks, client, scheduler)
    df = pd.DataFrame(rows, columns=CSV_COLUMNS)
    if len(radii) > 1:
        df.insert(2, "radius", [t[3] for t in tasks])
    return df


def _from_here(p: Any) -> str:
    """``p`` from the caller's folder: joined to it when relative, not normalised (``link/..``
    through a symbolic link is not the folder ``..`` of ``link``'s name)."""
    p = os.fspath(p)
    return p if os.path.isabs(p) else os.path.join(os.getcwd(), p)


def _gather(tasks: list[tuple[Any, ...]], client: Any, scheduler: str | None) -> list[Any]:
    """Runs the sweep's cells on ``client`` (or a cluster of its own) and gathers their rows.

    On Ctrl-C or any failure the cells not gathered are cancelled before the sweep lets its
    output folder go: they went on writing run folders into it after the sweep had returned
    and another sweep or bench had taken the folder (hostile pass). Cells already running on
    a client's workers cannot be stopped by Dask and may still finish theirs; the sweep's own
    cluster is closed, which stops them."""
    Client = _extra("distributed").Client

    own = None
    if client is None:
        address = scheduler or os.environ.get("CCPP_DASK_SCHEDULER")
        try:
            own = Client(address) if address else Client(processes=True)
        except (ValueError, OSError, TimeoutError) as e:
            # (a scheduler name Dask does not take, `"synchronous"`, raised Dask's own
            # ValueError; an address nobody answers, an OSError)
            raise _ccpp.CcppError(
                f"cannot reach the Dask scheduler {address!r}: {e}" if address else f"cannot start a local Dask cluster: {e}"
            ) from e
        client = own
    futures: list[Any] = []
    try:
        futures = [client.submit(_run_cell, *t, pure=False) for t in tasks]
        return list(client.gather(futures))
    except BaseException:
        if futures:
            client.cancel(futures)
        raise
    finally:
        if own is not None:
            own.close()
