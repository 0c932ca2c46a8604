"""ccpp.sweep on a local two-worker Dask cluster against `ccpp bench`."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

pd = pytest.importorskip("pandas")
distributed = pytest.importorskip("distributed")

import ccpp  # noqa: E402
from conftest import COMPARE_MAPS, write_room  # noqa: E402

# Columns that differ between any two runs (timing) or by design (output folder).
VOLATILE = ["wall_time_s", "dir"]


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    )
    c = distributed.Client(cluster)
    # Both workers up before the sweep starts (a loaded machine starts them slowly).
    c.wait_for_workers(2, timeout=120)
    yield c
    c.close()
    cluster.close()


def test_sweep_equals_bench(shared_maps: Path, ccpp_bin: str, tmp_path: Path, client) -> None:
    maps = [str(shared_maps / f"{m}.yaml") for m in COMPARE_MAPS[:2]]
    planners = [p["name"] for p in ccpp.planners()]
    bench_out = tmp_path / "bench"
    p = subprocess.run(
        [ccpp_bin, "bench", "--maps", *maps, "--planners", ",".join(planners),
         "--out", str(bench_out), "--quiet", "--jobs", "2"],
        capture_output=True, text=True, check=False,
    )
    assert p.returncode == 0, p.stderr
    expected = pd.read_csv(
        bench_out / "results.csv", keep_default_na=False, na_values=[""], float_precision="round_trip"
    )
    sweep_out = tmp_path / "sweep"
    got = ccpp.sweep(maps, planners, [0.15], client=client, out=sweep_out)
    # (ccpp's stamp, as in a bench's folder: `ccpp bench` refuses a folder of files without it)
    assert (sweep_out / ".ccpp").is_file()
    assert list(got.columns) == ccpp.CSV_COLUMNS == list(expected.columns)
    assert len(got) == len(expected) == len(maps) * len(planners)
    # The workers really ran in two processes. Asked of the scheduler: `scheduler_info()` is
    # the client's cached copy, which a loaded CI run once found empty after the sweep.
    assert len(client.nthreads()) == 2
    a = expected.drop(columns=VOLATILE).reset_index(drop=True)
    b = got.drop(columns=VOLATILE).reset_index(drop=True)
    b = b.astype(a.dtypes.to_dict())
    pd.testing.assert_frame_equal(a, b, check_exact=True)
    # The run folders hold the bench's files.
    for row in got.itertuples():
        assert (Path(row.dir) / "metrics.json").is_file()
        rel = Path(row.dir).relative_to(sweep_out)
        assert (bench_out / rel / "trace.jsonl").read_bytes() == (Path(row.dir) / "trace.jsonl").read_bytes()
    # A sweep into the bench's folder is refused before any run: it writes no summary, and its
    # runs (another radius) replaced run folders that the bench's results.csv went on telling.
    summary = (bench_out / "results.csv").read_bytes()
    run = bench_out / "runs" / COMPARE_MAPS[0] / planners[0] / "metrics.json"
    before = run.read_bytes()
    with pytest.raises(ccpp.CcppError, match=r"holds plots, the summary of an earlier ccpp bench"):
        ccpp.sweep(maps[:1], planners[:1], [0.2], client=client, out=bench_out)
    assert (bench_out / "results.csv").read_bytes() == summary
    assert run.read_bytes() == before
    # Its own folder is taken again (the run folders replaced whole).
    again = ccpp.sweep(maps[:1], planners[:1], [0.2], client=client, out=sweep_out)
    assert json.loads((Path(again.dir[0]) / "metrics.json").read_text())["robot_radius_m"] == 0.2


def test_sweep_radii_and_errors(room: Path, tmp_path: Path, client) -> None:
    # A map file that does not load is a row of errors, as in `ccpp bench`.
    bad = tmp_path / "broken.yaml"
    bad.write_text("image: nope.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n")
    df = ccpp.sweep([str(room), str(bad)], ["bsa", "bcd"], [0.15, 0.2], client=client)
    assert list(df.columns) == ccpp.CSV_COLUMNS[:2] + ["radius"] + ccpp.CSV_COLUMNS[2:]
    assert len(df) == 2 * 2 * 2
    ok = df[df["map"] == "room"]
    assert (ok["status"] == "ok").all()
    assert sorted(ok["robot_radius_m"].unique().tolist()) == [0.15, 0.2]
    err = df[df["map"] == "broken"]
    assert (err["status"] == "error").all() and err["error"].str.contains("broken.yaml").all()
    assert err["effective_coverage"].isna().all()
    with pytest.raises(ccpp.CcppError, match="unknown planner"):
        ccpp.sweep([str(room)], ["nope"], client=client)
    # A radius is a number: True ran at 1.0 m and "0.2" at 0.2 m.
    for radii in ([True], ["0.2"]):
        with pytest.raises(ccpp.CcppError, match="radii must be numbers"):
            ccpp.sweep([str(room)], ["bsa"], radii, client=client)


def test_sweep_refuses_what_it_would_ignore(room: Path, tmp_path: Path, client) -> None:
    from conftest import write_room

    # A scheduler beside a client would be ignored.
    with pytest.raises(ccpp.CcppError, match="give one of them"):
        ccpp.sweep([str(room)], ["bsa"], client=client, scheduler="tcp://127.0.0.1:1")
    # An empty list is not "every planner".
    with pytest.raises(ccpp.CcppError, match="planners is empty"):
        ccpp.sweep([str(room)], [], client=client)
    # Radii are checked before any task starts.
    with pytest.raises(ccpp.CcppError, match="robot radius"):
        ccpp.sweep([str(room)], ["bsa"], [0.15, float("nan")], client=client)
    with pytest.raises(ccpp.CcppError, match="tool radius"):
        ccpp.sweep([str(room)], ["bsa"], [0.15], tool_radius=0.2, client=client)
    # As `ccpp bench`: a map, planner or radius named twice runs once (two runs would write the
    # same folder), and maps sharing a file stem get distinct names, rows and folders.
    other = tmp_path / "b"
    other.mkdir()
    room2 = write_room(other)
    out = tmp_path / "out"
    df = ccpp.sweep([str(room), str(room), str(room2)], ["bsa", "bsa"], [0.15, 0.15], client=client, out=out)
    assert df["map"].tolist() == [f"{room.parent.name}-room", "b-room"]
    assert (df["status"] == "ok").all() and len(set(df["dir"])) == 2
    for row in df.itertuples():
        assert json.loads((Path(row.dir) / "metrics.json").read_text())["map"] == row.map


def test_sweep_refuses_a_missing_map_and_a_foreign_folder_up_front(room: Path, tmp_path: Path, client) -> None:
    # A map that does not exist: refused before any run (`ccpp bench --maps` refuses it), not
    # turned into rows of errors.
    missing = tmp_path / "missing.yaml"
    with pytest.raises(ccpp.CcppError, match=r"missing\.yaml: no such file"):
        ccpp.sweep([str(room), str(missing)], ["bcd"], client=client)
    # `out` holding files a sweep did not write: refused (as `ccpp bench --out`), nothing written.
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    with pytest.raises(ccpp.CcppError, match="holds notes.txt"):
        ccpp.sweep([str(room)], ["bcd"], client=client, out=out)
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]
    # A folder of a sweep (or a bench) is reused.
    own = tmp_path / "own"
    ccpp.sweep([str(room)], ["bcd"], client=client, out=own)
    df = ccpp.sweep([str(room)], ["bcd"], client=client, out=own)
    assert (df["status"] == "ok").all()


def test_sweep_takes_one_planner_name_and_none_as_defaults(room: Path, client) -> None:
    # A string is one planner, not its letters ("b", "s", "a" are no planners).
    df = ccpp.sweep(str(room), "bsa", client=client)
    assert df["planner"].tolist() == ["bsa"]
    # One radius as a number; None for every keyword is its default.
    one = ccpp.sweep(str(room), ["bsa"], 0.2, client=client)
    assert one["robot_radius_m"].tolist() == [0.2]
    d = ccpp.sweep(
        str(room), ["bsa"], None, tool_radius=None, inflate=None, max_memory_mb=None,
        out=None, client=client, scheduler=None,
    )
    assert d.drop(columns=VOLATILE).equals(df.drop(columns=VOLATILE))
    # Spaces around a name are dropped, as ccpp.run and `ccpp bench --planners` drop them.
    spaced = ccpp.sweep(str(room), [" bsa "], client=client)
    assert spaced["planner"].tolist() == ["bsa"]
    # Any iterable of radii, a generator too (it was read up by the check before the sweep
    # took it: "radii is empty"); a radius that is no iterable nor number, and planners as
    # bytes, are refused naming the value (hostile pass).
    gen = ccpp.sweep(str(room), ["bsa"], (r for r in [0.2, 0.25]), client=client)
    assert gen["robot_radius_m"].tolist() == [0.2, 0.25]
    # A 0-d numpy array is a number, as ccpp.run takes it (a sweep refused np.array(0.2)).
    zero_d = ccpp.sweep(str(room), ["bsa"], np.array(0.2), client=client)
    assert zero_d["robot_radius_m"].tolist() == [0.2]
    listed = ccpp.sweep(str(room), ["bsa"], [np.array(0.25)], client=client)
    assert listed["robot_radius_m"].tolist() == [0.25]
    with pytest.raises(ccpp.CcppError, match="radii must be"):
        ccpp.sweep(str(room), ["bsa"], np.array(True), client=client)
    with pytest.raises(ccpp.CcppError, match=r"radii must be a number or numbers \(metres\), got True"):
        ccpp.sweep(str(room), ["bsa"], True, client=client)
    with pytest.raises(ccpp.CcppError, match=r"planners must be names \(str\), got b'bsa'"):
        ccpp.sweep(str(room), b"bsa", client=client)
    with pytest.raises(ccpp.CcppError, match=r"client must be a distributed.Client, got <object"):
        ccpp.sweep(str(room), ["bsa"], client=object())


def test_sweep_without_its_extra_says_how_to_install_it(room: Path, monkeypatch) -> None:
    import importlib

    real = importlib.import_module

    def without_pandas(name: str, *args, **kwargs):
        if name == "pandas":
            raise ModuleNotFoundError("No module named 'pandas'", name="pandas")
        return real(name, *args, **kwargs)

    monkeypatch.setattr(importlib, "import_module", without_pandas)
    with pytest.raises(ModuleNotFoundError, match=r"needs pandas: install the sweep extra") as e:
        ccpp.sweep(str(room), ["bsa"])
    assert e.value.name == "pandas"


def test_sweep_status_of_a_stalled_run_is_stalled(shared_maps: Path, monkeypatch) -> None:
    # As `ccpp bench`'s results.csv: a run the simulator stopped says why instead of "ok". A
    # sweep has no noise settings (nor has `ccpp bench` but through --config), so the row is
    # built from the metrics of a `ccpp.run` that stalls, in place of the worker's run.
    # (rect-boustrophedon's bumper reaction no longer stalls: the plan replayed blindly does.)
    r = ccpp.run(
        str(shared_maps / "aws_small_house.yaml"), "rect-boustrophedon",
        options={"bumper_reaction": False, "exec": {"pid": {"noise": {
            "seed": 6, "linear_rel_std": 0.2, "angular_rel_std": 0.2, "heading_drift_std": 0.2,
        }}}},
    )
    assert r.metrics["stop_reason"] == "stalled"
    from ccpp import _ccpp, sweeps

    monkeypatch.setattr(_ccpp, "bench_run", lambda *a, **k: (r.metrics, None, []))
    row = sweeps._run_cell("m.yaml", "m", "rect-boustrophedon", 0.15, None, None, None, None, None)
    assert row["status"] == "stalled" and row["error"] is None
    done = ccpp.run(str(shared_maps / "teb_maze.yaml"), "bcd")
    monkeypatch.setattr(_ccpp, "bench_run", lambda *a, **k: (done.metrics, None, []))
    assert sweeps._run_cell("m.yaml", "m", "bcd", 0.15, None, None, None, None, None)["status"] == "ok"


def test_sweep_reports_warnings_as_bench_does(room: Path, ccpp_bin: str, tmp_path: Path, client) -> None:
    # ba-star's tiles (the robot's diameter, 0.3 m) are wider than a 0.2 m tool: `ccpp run`
    # warns, and so do the bench's and the sweep's `warnings` column (it was not carried).
    bench_out = tmp_path / "bench"
    p = subprocess.run(
        [ccpp_bin, "bench", "--maps", str(room), "--planners", "ba-star,bcd", "--tool-radius",
         "0.1", "--out", str(bench_out), "--quiet"],
        capture_output=True, text=True, check=False,
    )
    assert p.returncode == 0, p.stderr
    expected = pd.read_csv(bench_out / "results.csv", keep_default_na=False, na_values=[""])
    got = ccpp.sweep(room, ["ba-star", "bcd"], tool_radius=0.1, client=client)
    assert list(got["warnings"].isna()) == list(expected["warnings"].isna()) == [False, True]
    assert got["warnings"][0] == expected["warnings"][0]
    assert got["warnings"][0].startswith("the tile side 0.3 m is wider than the tool sweeps")
    assert got["warnings"][0] in ccpp.run(room, "ba-star", tool_radius=0.1).warnings


class _ElsewhereClient:
    """A Dask client stand-in whose worker runs each task in another folder, as a worker of
    a real cluster started elsewhere does (a local cluster's workers share the caller's)."""

    def __init__(self, cwd: Path) -> None:
        self.cwd = cwd

    def submit(self, fn, *args, pure=True):  # noqa: ANN001, ANN201, ARG002
        here = os.getcwd()
        os.chdir(self.cwd)
        try:
            return fn(*args)
        finally:
            os.chdir(here)

    def gather(self, futures):  # noqa: ANN001, ANN201
        return futures


def test_relative_paths_mean_the_callers_folder_on_every_worker(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Before: the worker read `maps/room.yaml` in its own folder (an error row), and with an
    # absolute map wrote `sw/runs/...` there while the row said ok and the caller's `sw`,
    # checked and locked, stayed empty.
    (tmp_path / "maps").mkdir()
    write_room(tmp_path / "maps")
    elsewhere = tmp_path / "elsewhere"
    (elsewhere / "maps").mkdir(parents=True)
    monkeypatch.chdir(tmp_path)
    client = _ElsewhereClient(elsewhere)
    df = ccpp.sweep("maps/room.yaml", ["bsa"], 0.15, client=client, out="sw")
    assert list(df["status"]) == ["ok"], df.to_dict("records")
    assert list(df["dir"]) == [str(Path("sw") / "runs" / "room" / "bsa")]
    assert (tmp_path / "sw" / "runs" / "room" / "bsa" / "metrics.json").is_file()
    assert not (elsewhere / "sw").exists()


def test_an_interrupted_sweep_cancels_its_cells() -> None:
    """Ctrl-C during a sweep left its Dask cells queued: they wrote run folders into the output
    folder after the sweep had let it go (hostile pass). The cells are cancelled first."""
    from ccpp import sweeps

    class Client:
        def __init__(self) -> None:
            self.cancelled: list = []

        def submit(self, fn, *args, pure=True):
            return ("future", args[1], args[2])

        def gather(self, futures):
            raise KeyboardInterrupt

        def cancel(self, futures):
            self.cancelled.extend(futures)

    c = Client()
    tasks = [("m.yaml", "m", p, 0.15, None, None, None, None, None) for p in ("bsa", "bcd")]
    with pytest.raises(KeyboardInterrupt):
        sweeps._gather(tasks, c, None)
    assert c.cancelled == [("future", "m", "bsa"), ("future", "m", "bcd")]


def test_a_scheduler_dask_refuses_leaves_no_folder(room: Path, tmp_path: Path) -> None:
    """A scheduler name Dask does not take (``"synchronous"``) raised Dask's own ValueError
    and left the output folder made, empty (hostile pass): a CcppError naming it, no folder."""
    out = tmp_path / "sw"
    with pytest.raises(ccpp.CcppError, match=r"^cannot reach the Dask scheduler 'synchronous': "):
        ccpp.sweep([str(room)], ["bsa"], out=out, scheduler="synchronous")
    assert not out.exists()
    # A folder that was there stays, with what it held.
    out.mkdir()
    (out / "runs").mkdir()
    with pytest.raises(ccpp.CcppError):
        ccpp.sweep([str(room)], ["bsa"], out=out, scheduler="synchronous")
    assert sorted(p.name for p in out.iterdir()) == ["runs"]
