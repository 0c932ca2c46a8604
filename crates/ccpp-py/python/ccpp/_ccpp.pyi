"""Type stubs of the ccpp extension module (re-exported by ``ccpp``)."""

import os
from typing import Any, Sequence, SupportsFloat

import numpy as np
import numpy.typing as npt

__version__: str

_Path = str | os.PathLike[str]

class CcppError(Exception):
    """A ccpp error; the message is the command line's one-line message."""

class Map:
    """An occupancy-grid map, loaded and prepared (overrides, georeference, inflation)."""

    @property
    def name(self) -> str: ...
    @property
    def path(self) -> str: ...
    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    @property
    def size(self) -> tuple[int, int]:
        """(width, height) in pixels."""
    @property
    def size_m(self) -> tuple[float, float]:
        """(width, height) in metres."""
    @property
    def resolution(self) -> float:
        """Metres per pixel."""
    @property
    def origin(self) -> tuple[float, float, float]:
        """(x, y, yaw) of the image's bottom-left corner."""
    @property
    def occupancy(self) -> npt.NDArray[np.uint8]:
        """(height, width), image layout (row 0 = top): 0 free, 1 occupied, 2 unknown."""
    def pixel_center(self, col: int, row: int) -> tuple[float, float]:
        """World (x, y) of the centre of pixel (col, row)."""

class RunResult:
    """A finished run."""

    @property
    def metrics(self) -> dict[str, Any]:
        """The keys of metrics.json."""
    @property
    def path(self) -> npt.NDArray[np.float64]:
        """Executed poses, (N, 3): x, y, theta (under PID execution the recorded ones: no
        pose inside a straight glide along the map's axes)."""
    @property
    def swept(self) -> npt.NDArray[np.bool_]:
        """Swept pixels, (height, width), image layout."""
    @property
    def accessible(self) -> npt.NDArray[np.bool_]:
        """Pixels the tool can reach from the start, (height, width), image layout."""
    @property
    def events(self) -> list[dict[str, Any]]:
        """Trace events as in trace.jsonl (with the step counter ``t``), except that every
        ``backtrack_list`` event holds its whole list as ``points`` (the file stores most of them
        as a ``delta`` against the list before)."""
    @property
    def stop(self) -> str:
        """``"done"``, ``"stalled"`` (no progress for 1000 motions in a row) or ``"max_steps"``."""
    @property
    def warnings(self) -> list[str]:
        """The warnings ``ccpp run`` prints (without ``warning: ``): a start whose free area
        reaches the map's border, an early stop, PID motions cut short, bumper contacts under
        odometry noise without landmarks, a run that never moved, a tool narrower than the
        map's pixels."""
    @property
    def notes(self) -> list[str]:
        """What ``ccpp run`` notes (without ``note: ``): a start outside the area, and how far
        the robot first drives to reach it. Empty otherwise."""
    @property
    def start(self) -> tuple[float, float, float]: ...
    @property
    def scenario_json(self) -> str:
        """The run.json text."""
    def save(self, folder: _Path, export: str | Sequence[str] | None = None) -> None:
        """Writes the files of ``ccpp run --out folder`` (``export``: ``--export`` formats).

        All or nothing: an older run's files in ``folder`` are replaced whole; a folder
        holding files ccpp did not write is refused (``CcppError``). Ctrl-C while the files
        are drawn raises ``KeyboardInterrupt`` once they are drawn, before ``folder`` is
        touched."""
    def waypoints(self, tolerance_m: float | None = 0.001) -> npt.NDArray[np.float64]:
        """Waypoints of the executed path, (N, 3): x, y, theta at segment ends (poses merged
        within ``tolerance_m``; ``None`` is the default)."""
    def export(self, format: str) -> str:
        """The text of ``ccpp run --export FORMAT``'s file (csv, json, nav-path, geojson)."""

class PlanResult:
    """A path planned on a known map (``ccpp plan``)."""

    @property
    def waypoints(self) -> npt.NDArray[np.float64]:
        """(N, 3): x, y, theta at segment ends."""
    @property
    def length_m(self) -> float: ...
    @property
    def finished(self) -> bool: ...
    @property
    def warnings(self) -> list[str]:
        """What ``ccpp plan`` warns of this plan (without ``warning: ``)."""
    @property
    def notes(self) -> list[str]:
        """What ``ccpp plan`` notes (without ``note: ``): a start outside the area."""
    def export(self, format: str) -> str:
        """The text of ``ccpp plan --export FORMAT``'s file (csv, json, nav-path, geojson)."""
    def save(self, folder: _Path, export: str | Sequence[str] | None = None) -> None:
        """Writes the exports (default csv and nav-path), as ``ccpp plan --out folder``."""

LOCK_FILE: str
STAMP_FILE: str
STAMP_TEXT: str
"""The lock file a ``ccpp bench`` or a sweep holds in its output folder."""

WARNINGS_SEPARATOR: str
"""Joins a run's warnings in one field of ``results.csv`` and of a sweep's ``warnings`` column."""

class FolderLock:
    """The lock a sweep holds on its output folder, the same as ``ccpp bench``'s: taken when
    made (``CcppError`` naming the holder's process when another bench or sweep holds it)."""

    def __init__(self, folder: _Path) -> None: ...
    def release(self) -> None:
        """Releases the lock and removes its file (again: nothing)."""
    @property
    def held(self) -> bool: ...

class Env:
    """Step-by-step coverage environment on the simulator's physics and sensor."""

    def __init__(
        self,
        map: Map | _Path,
        *,
        radius: SupportsFloat | None = 0.15,
        tool_radius: SupportsFloat | None = None,
        sensor_range: float | None = None,
        start: Sequence[float] | None = None,
        exec: str | None = "ideal",
        max_steps: int | None = None,
        area: Any = None,
        keepout: Any = None,
        max_memory_mb: int | None = None,
    ) -> None:
        """``max_steps`` (>= 1) truncates episodes; values are validated as a run's. ``area``
        and ``keepout`` are shown to the sensor as walls but do not stop the robot: a step into
        a keep-out (or out of the area) counts in ``metrics()["keepout_violations"]``.
        ``max_memory_mb`` (default: the limit ``map`` was loaded within, else 4096) bounds the
        map's load and what an episode holds, as a run's. One Env may be used from several
        threads: calls take turns."""
    def reset(self, seed: int | None = None) -> tuple[dict[str, Any], dict[str, Any]]:
        """Starts an episode; returns (observation, info). A seed draws a random free start
        (refused for an Env given ``start=``)."""
    def step(
        self, action: Sequence[Any]
    ) -> tuple[dict[str, Any], float, bool, bool, dict[str, Any]]:
        """``("rotate", a)``, ``("translate", d)`` or ``("move_to", x, y)`` ->
        (observation, reward m², terminated, truncated, info). Truncated after ``max_steps``
        actions, or when the episode's recorded path passes ``max_memory_mb``
        (``info["memory_limit"]`` is then True)."""
    @property
    def map(self) -> Map: ...
    @property
    def sensor_range(self) -> float: ...
    @property
    def radius(self) -> float: ...
    @property
    def tool_radius(self) -> float: ...
    @property
    def scan_side(self) -> int: ...
    @property
    def swept(self) -> npt.NDArray[np.bool_]: ...
    @property
    def accessible(self) -> npt.NDArray[np.bool_]: ...
    @property
    def reachable(self) -> npt.NDArray[np.bool_]:
        """Pixel centres the robot centre can reach, (height, width), image layout."""
    def metrics(self) -> dict[str, Any]:
        """Metrics of the episode so far (planner ``"env"``)."""

def load_map(
    path: _Path,
    *,
    resolution: float | None = None,
    origin: Sequence[float] | None = None,
    occupied_thresh: float | None = None,
    free_thresh: float | None = None,
    inflate: float | None = None,
    georef: _Path | None = None,
    name: str | None = None,
    max_memory_mb: int | None = None,
) -> Map:
    """Loads a ROS map_server YAML (with its image) or a bare PGM/PNG; an image whose pixels
    alone would need more than ``max_memory_mb`` (default 4096) in a run is refused from its
    header, before it is decoded. A limit given here stays with the map: it is the default
    ``max_memory_mb`` of ``run``, ``plan`` and ``Env`` on it."""

def run(
    map: Map | _Path, planner: str | None = "ba-star", radius: SupportsFloat | None = 0.15, **options: Any
) -> RunResult:
    """Runs a planner; options are scenario fields (``tool_radius``, ``start``,
    ``sensor_range``, ``exec``, ``odometry_noise`` (LIN or ``(LIN, ANG, DRIFT)``, as
    ``--odometry-noise``), ``landmarks`` (a file or a list of ``(id, x, y[, theta])``),
    ``seed`` (of random-bounce and of the noise), ``max_steps``, ``max_memory_mb``, ``name``,
    ``area``, ``keepout``) or the planner's own options (directly or in ``options={...}``; a key given
    both ways must have one value). Options that do not apply are refused; ``exec="pid"`` runs
    the planner's own PID settings, ``exec="ideal"`` beside them is refused. A keyword given as
    ``None`` is its default, as if left out. ``max_memory_mb`` (default: the limit a ``Map``
    was loaded within, else 4096) bounds the map's load too.
    Ctrl-C raises ``KeyboardInterrupt`` at once (the run ends on its own thread, its result
    dropped)."""

def plan(
    map: Map | _Path, planner: str | None = "bcd", radius: SupportsFloat | None = 0.15, **options: Any
) -> PlanResult:
    """Plans a path with a known-map planner (``ccpp plan``); options as for ``run`` where they
    apply to a plan (refused: ``exec``, the planner's execution settings, ``sensor_range``, a
    start heading, ``tool_radius`` for rect-boustrophedon)."""

def bench_run(
    map_path: _Path,
    planner: str,
    radius: SupportsFloat | None = 0.15,
    tool_radius: SupportsFloat | None = None,
    inflate: float | None = None,
    max_memory_mb: int | None = None,
    out: _Path | None = None,
    name: str | None = None,
) -> tuple[dict[str, Any] | None, str | None, list[str]]:
    """One ``ccpp bench`` run: (metrics, None, warnings) or, when the run fails, (None, error
    message, []); the warnings are those ``ccpp run`` prints (without ``warning: ``); ``name``
    is the map's name in the results (default its file stem). Arguments a run refuses before
    it starts (an unknown planner, a bad robot or memory limit) raise ``CcppError``."""

def expand_maps(items: list[_Path]) -> list[Any]:
    """The map files that files and folders stand for, as ``ccpp bench --maps`` takes them."""

def name_maps(paths: list[_Path]) -> list[tuple[int, str]]:
    """The maps a sweep runs and their names, as ``ccpp bench`` names them: ``(index in
    paths, name)`` for every map kept (a file named twice is run once), in order."""

def check_robot(radius: float, tool_radius: SupportsFloat | None = None) -> None:
    """Raises CcppError for a robot a run would refuse."""

def planners() -> list[dict[str, Any]]:
    """name, offline, description and default options of every planner."""
