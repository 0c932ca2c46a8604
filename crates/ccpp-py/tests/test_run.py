"""ccpp.run / load_map / save against the command line."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

import ccpp
from conftest import COMPARE_MAPS

PLANNERS = [p["name"] for p in ccpp.planners()]


def cli(binary: str, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([binary, *args], capture_output=True, text=True, check=False)


def without_time(m: dict) -> dict:
    return {k: v for k, v in m.items() if k != "wall_time_s"}


def test_planners_lists_the_catalogue() -> None:
    names = [p["name"] for p in ccpp.planners()]
    assert "ba-star" in names and "bcd" in names and len(names) == len(set(names))
    ba = next(p for p in ccpp.planners() if p["name"] == "ba-star")
    assert ba["offline"] is False and "smoothing" in ba["options"]


@pytest.mark.parametrize("map_name", COMPARE_MAPS)
@pytest.mark.parametrize("planner", PLANNERS)
def test_run_equals_cli(shared_maps: Path, ccpp_bin: str, tmp_path: Path, map_name: str, planner: str) -> None:
    path = shared_maps / f"{map_name}.yaml"
    out = tmp_path / "cli"
    p = cli(ccpp_bin, "run", "--map", str(path), "--planner", planner, "--out", str(out), "--json")
    assert p.returncode == 0, p.stderr
    expected = json.loads(p.stdout)
    r = ccpp.run(ccpp.load_map(path), planner=planner)
    assert without_time(r.metrics) == without_time(expected)
    # The same files as the CLI.
    py_out = tmp_path / "py"
    r.save(py_out)
    for name in ("path.csv", "trace.jsonl", "run.json"):
        assert (py_out / name).read_bytes() == (out / name).read_bytes(), name
    assert without_time(json.loads((py_out / "metrics.json").read_text())) == without_time(expected)
    assert (py_out / "coverage.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # Arrays agree with the metrics.
    m = r.metrics
    assert r.path.shape[1] == 3 and r.path.shape[0] >= 1
    seg = np.diff(r.path[:, :2], axis=0)
    assert np.hypot(seg[:, 0], seg[:, 1]).sum() == pytest.approx(m["path_length_m"], rel=1e-9, abs=1e-9)
    acc = r.accessible
    assert acc.dtype == bool and acc.shape == (r_height(path), r_width(path))
    eff = (r.swept & acc).sum() / acc.sum()
    assert eff == pytest.approx(m["effective_coverage"], abs=1e-12)
    assert sum(1 for e in r.events if e["event"] == "collision") == m["collisions"]


def r_width(path: Path) -> int:
    return ccpp.load_map(path).width


def r_height(path: Path) -> int:
    return ccpp.load_map(path).height


def test_map_properties(room: Path) -> None:
    m = ccpp.load_map(room)
    assert (m.width, m.height) == (60, 40) and m.size == (60, 40)
    assert m.resolution == 0.05 and m.origin == (0.0, 0.0, 0.0)
    assert m.size_m == pytest.approx((3.0, 2.0))
    occ = m.occupancy
    assert occ.shape == (40, 60) and occ.dtype == np.uint8
    assert occ[0].tolist() == [1] * 60 and occ[20, 30] == 0
    # Overrides go through the loader.
    assert ccpp.load_map(room, resolution=0.1).size_m == pytest.approx((6.0, 4.0))
    assert ccpp.load_map(room, inflate=0.1).occupancy.sum() > occ.sum()
    assert ccpp.load_map(room, name="box").name == "box"


def test_options_change_the_run_as_the_cli_flags(shared_maps: Path, ccpp_bin: str, tmp_path: Path) -> None:
    path = shared_maps / "teb_maze.yaml"
    m = ccpp.load_map(path)
    base = ccpp.run(m, "ba-star")
    off = ccpp.run(m, "ba-star", smoothing=False)
    assert without_time(off.metrics) != without_time(base.metrics)
    p = cli(ccpp_bin, "run", "--map", str(path), "--planner", "ba-star", "--smoothing", "off",
            "--out", str(tmp_path), "--json")
    assert without_time(off.metrics) == without_time(json.loads(p.stdout))
    # The same through options={...}.
    assert without_time(ccpp.run(m, "ba-star", options={"smoothing": False}).metrics) == without_time(off.metrics)
    r2 = ccpp.run(m, "bsa", radius=0.2, tool_radius=0.15)
    assert r2.metrics["robot_radius_m"] == 0.2 and r2.metrics["tool_radius_m"] == 0.15
    # A random-bounce seed changes the path.
    a = ccpp.run(m, "random-bounce", seed=1)
    b = ccpp.run(m, "random-bounce", seed=2)
    assert a.metrics["path_length_m"] != b.metrics["path_length_m"] or not np.array_equal(a.path, b.path)


def test_errors_are_the_cli_messages(ccpp_bin: str, tmp_path: Path, room: Path) -> None:
    missing = tmp_path / "nope.yaml"
    p = cli(ccpp_bin, "run", "--map", str(missing), "--planner", "ba-star", "--out", str(tmp_path / "o"))
    assert p.returncode == 1
    line = p.stderr.strip()
    assert line.startswith("error: ") and "\n" not in line
    with pytest.raises(ccpp.CcppError) as e:
        ccpp.load_map(missing)
    assert str(e.value) == line.removeprefix("error: ")
    # A robot too big for the room.
    p = cli(ccpp_bin, "run", "--map", str(room), "--planner", "ba-star", "--radius", "5", "--out", str(tmp_path / "o"))
    with pytest.raises(ccpp.CcppError) as e:
        ccpp.run(ccpp.load_map(room), radius=5.0)
    assert str(e.value) == p.stderr.strip().removeprefix("error: ")
    # Invalid values are refused by the scenario, with the CLI's wording.
    p = cli(ccpp_bin, "run", "--map", str(room), "--planner", "ba-star", "--radius=-1", "--out", str(tmp_path / "o"))
    with pytest.raises(ccpp.CcppError) as e:
        ccpp.run(room, radius=-1.0)
    assert str(e.value) in p.stderr
    with pytest.raises(ccpp.CcppError, match="unknown planner"):
        ccpp.run(room, planner="nope")
    with pytest.raises(ccpp.CcppError, match="unknown field"):
        ccpp.run(room, planner="ba-star", nonsense=1)
    with pytest.raises(ccpp.CcppError, match="sensor_range does not apply to bcd"):
        ccpp.run(room, planner="bcd", sensor_range=1.0)
    # ba-star, bsa and bsa-bfs decide from their neighbour tiles alone: a range changed
    # nothing in their runs, and is refused as the command line refuses it.
    for p in ("ba-star", "bsa", "bsa-bfs"):
        with pytest.raises(ccpp.CcppError, match=rf"^sensor_range does not apply to {p} \(it applies to random-bounce, ba-star-extended and bsa-extended; {p} decides from its neighbour tiles alone"):
            ccpp.run(room, planner=p, sensor_range=3.0)
    assert ccpp.run(room, planner="ba-star-extended", sensor_range=3.0).metrics["collisions"] == 0
    with pytest.raises(ccpp.CcppError, match="seed does not apply to ba-star"):
        ccpp.run(room, planner="ba-star", seed=3)
    with pytest.raises(ccpp.CcppError, match="side"):
        ccpp.run(room, planner="ba-star", side="left")  # a bsa option given to ba-star


def test_runs_release_the_gil(room: Path) -> None:
    """Two runs in threads finish and agree (the GIL is released inside)."""
    from concurrent.futures import ThreadPoolExecutor

    m = ccpp.load_map(room)
    with ThreadPoolExecutor(2) as ex:
        rs = list(ex.map(lambda _: ccpp.run(m, "bsa").metrics, range(2)))
    assert without_time(rs[0]) == without_time(rs[1])


def test_save_replaces_the_folder_whole(room: Path, tmp_path: Path) -> None:
    """`save` wrote file by file into the folder: a second run saved there kept the first run's
    exports beside its own files (a mixed folder), and a folder of the user's files was written
    into. It is now all or nothing, as `ccpp run --out` and `ccpp plan --out`."""
    out = tmp_path / "out"
    ccpp.run(room, "bsa").save(out, export=["geojson", "csv"])
    ccpp.run(room, "bcd").save(out)
    # (every folder ccpp writes holds its `.ccpp` stamp: a folder of files named as ccpp's
    # without it is refused, so a user's own `path.csv` is never deleted)
    run_files = [".ccpp", "coverage.png", "metrics.json", "path.csv", "run.json", "trace.jsonl"]
    assert sorted(p.name for p in out.iterdir()) == run_files
    assert json.loads((out / "metrics.json").read_text())["planner"] == "bcd"
    ccpp.plan(room, "bcd").save(out)
    assert sorted(p.name for p in out.iterdir()) == [".ccpp", "nav_path.yaml", "waypoints.csv"]
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("mine")
    with pytest.raises(ccpp.CcppError, match="holds notes.txt, which ccpp did not write"):
        ccpp.run(room, "bsa").save(mine)
    with pytest.raises(ccpp.CcppError, match="holds notes.txt, which ccpp did not write"):
        ccpp.plan(room, "bcd").save(mine)
    assert [p.name for p in mine.iterdir()] == ["notes.txt"]
    (mine / "notes.txt").unlink()
    (mine / "path.csv").write_text("mine")
    with pytest.raises(ccpp.CcppError, match="holds path.csv but no .ccpp stamp"):
        ccpp.run(room, "bsa").save(mine)
    assert (mine / "path.csv").read_text() == "mine"
    (mine / "path.csv").unlink()
    (mine / "notes.txt").write_text("mine")
    # A path through `..` and no staging folder left anywhere.
    ccpp.run(room, "bsa").save(tmp_path / "dd" / ".." / "dd")
    assert sorted(p.name for p in (tmp_path / "dd").iterdir()) == run_files
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dd", "mine", "out", "room.pgm", "room.yaml"]
    # Staging folders of a killed process beside the folder are removed (they stayed for good;
    # hostile pass), and a folder inside a run folder is refused (the next run into the run
    # folder would delete it).
    dead = tmp_path / ".out.ccpp-new-4294967295-0"
    dead.mkdir()
    (dead / "metrics.json").write_text("{}")
    ccpp.run(room, "bsa").save(out)
    assert not dead.exists()
    with pytest.raises(ccpp.CcppError, match="lies inside the run folder"):
        ccpp.run(room, "bsa").save(out / "inner")
    assert sorted(p.name for p in out.iterdir()) == run_files


def test_errors_name_each_cause_once(room: Path, ccpp_bin: str, tmp_path: Path) -> None:
    """Python's errors repeated a cause the message already held (`cannot read DIR: not a
    regular file: not a regular file`); they are the command line's lines."""
    with pytest.raises(ccpp.CcppError) as e:
        ccpp.load_map(tmp_path)
    assert str(e.value) == f"cannot read {tmp_path}: a folder, not a map: give a map_server YAML or an image"
    p = cli(ccpp_bin, "run", "--map", str(room), "--planner", "bsa", "--start", "0.02,0.02", "--out", str(tmp_path / "o"))
    assert p.returncode == 1 and p.stderr.startswith("error: ")
    with pytest.raises(ccpp.CcppError) as e:
        ccpp.run(room, "bsa", start=(0.02, 0.02))
    assert str(e.value) == p.stderr.strip().removeprefix("error: ")


def test_whole_number_options_name_their_range(room: Path) -> None:
    """`max_steps=2**70` was refused as not `>= 0`, and `Env.reset(seed=-1)` raised an
    `OverflowError` where `run(seed=-1)` raises `CcppError`."""
    with pytest.raises(ccpp.CcppError, match=r"max_steps must be a whole number from 1 to 18446744073709551615, got 1180591620717411303424"):
        ccpp.run(room, "bsa", max_steps=2**70)
    # The range named is the one taken (it said "from 0", and 0 was then refused).
    for kw in ("max_steps", "max_memory_mb"):
        with pytest.raises(ccpp.CcppError, match=f"{kw} must be a whole number from 1 to"):
            ccpp.run(room, "bsa", **{kw: -1})
    env = ccpp.Env(room)
    for bad in (-1, 2**70):
        with pytest.raises(ccpp.CcppError, match=r"seed must be a whole number from 0 to 18446744073709551615"):
            env.reset(seed=bad)
    assert env.reset(seed=3)[1] == ccpp.Env(room).reset(seed=3)[1]


def test_bools_are_not_numbers(room: Path, tmp_path: Path) -> None:
    """`radius=True` ran with a 1 m robot: a bool is an `int` in Python, and number arguments
    took it as 1. Every number argument refuses bools; the same numbers as floats are taken."""
    for call in (
        lambda: ccpp.run(room, "bsa", radius=True),
        lambda: ccpp.plan(room, "bcd", radius=True),
        lambda: ccpp.Env(room, radius=True),
        lambda: ccpp.load_map(room, inflate=True),
        lambda: ccpp.load_map(room, origin=(0.0, False, 0.0)),
        lambda: ccpp.run(room, "bsa").waypoints(tolerance_m=True),
    ):
        with pytest.raises(TypeError, match="not bool"):
            call()
    # Keyword options read as numbers (tool_radius, sensor_range, Env's max_steps) refuse
    # bools too, as CcppErrors naming them.
    with pytest.raises(ccpp.CcppError, match="max_steps must be a whole number, got True"):
        ccpp.Env(room, max_steps=True)
    # A start holding a bool, as `run` says it.
    for call in (ccpp.Env, lambda *a, **k: ccpp.run(*a, "bsa", **k)):
        with pytest.raises(ccpp.CcppError, match=r"start expects \(x, y\) or \(x, y, theta\), got \(True, 0.5\)"):
            call(room, start=(True, 0.5))
    with pytest.raises(ccpp.CcppError, match="tool_radius must be a number, got True"):
        ccpp.run(room, "bsa", tool_radius=True)
    with pytest.raises(ccpp.CcppError, match="sensor_range must be a number, got False"):
        ccpp.run(room, "random-bounce", sensor_range=False)
    assert ccpp.run(room, "bsa", radius=0.1).metrics["robot_radius_m"] == 0.1


def test_save_under_a_file_names_the_file(room: Path, tmp_path: Path) -> None:
    """Saving into `notes.txt/run` said only "File exists"; the message names the file."""
    notes = tmp_path / "notes.txt"
    notes.write_text("keep me")
    with pytest.raises(ccpp.CcppError) as e:
        ccpp.run(room, "bsa").save(notes / "run")
    assert str(e.value) == f"cannot create output folder {notes / 'run'}: {notes} is a file, not a folder"
    assert notes.read_text() == "keep me"


def test_save_refuses_a_folder_holding_an_input(room: Path, tmp_path: Path) -> None:
    """A map named `coverage.png` in the folder was replaced by the run's picture (a plan's
    save deleted it); the save is refused and the map kept, as `ccpp run` and `ccpp plan` do."""
    folder = tmp_path / "out"
    folder.mkdir()
    (folder / ".ccpp").write_text("stamp")  # (a folder ccpp wrote: else refused for that)
    map_png = folder / "coverage.png"
    map_png.write_bytes((room.parent / "room.pgm").read_bytes())  # sniffed by content
    before = map_png.read_bytes()
    for result in (ccpp.run(map_png, "bsa"), ccpp.plan(map_png, "bcd")):
        with pytest.raises(ccpp.CcppError, match="coverage.png, an input of this run"):
            result.save(folder)
        assert map_png.read_bytes() == before
        assert sorted(p.name for p in folder.iterdir()) == [".ccpp", "coverage.png"]
    # A landmarks file named as a run file (`path.csv`) in the folder: refused too.
    other = tmp_path / "other"
    other.mkdir()
    (other / ".ccpp").write_text("stamp")
    marks = other / "path.csv"
    marks.write_text("1,0.5,0.5\n2,2.5,1.5\n")
    noisy = ccpp.run(room, "bsa", odometry_noise=0.01, seed=1, landmarks=marks)
    with pytest.raises(ccpp.CcppError, match="path.csv, an input of this run"):
        noisy.save(other)
    assert marks.read_text() == "1,0.5,0.5\n2,2.5,1.5\n"


def test_scenario_json_is_the_saved_run_json(room: Path, tmp_path: Path) -> None:
    """`scenario_json` lacked the run.json's `map_digest`, and gave the start inside the area
    (after the approach) where run.json gives the start the run began at."""
    for kw in ({}, {"start": (0.5, 0.5, 0.0), "area": [1.0, 0.6, 2.5, 1.6]}):
        r = ccpp.run(room, "bsa", **kw)
        out = tmp_path / f"s{len(kw)}"
        r.save(out)
        assert r.scenario_json == (out / "run.json").read_text()
        assert len(json.loads(r.scenario_json)["map_digest"]) == 16
    assert json.loads(r.scenario_json)["start"] == [0.5, 0.5, 0.0]


def test_save_refuses_a_bench_run_folder(room: Path, ccpp_bin: str, tmp_path: Path) -> None:
    # As `ccpp run --out`: a bench's run folder (it holds bench-key.txt) is the bench's; a run
    # saved there would no longer match its results.csv.
    out = tmp_path / "b"
    p = subprocess.run([ccpp_bin, "bench", "--quiet", "--planners", "bsa", "--maps", str(room), "--out", str(out)], capture_output=True, text=True, check=False)
    assert p.returncode == 0, p.stderr
    run_dir = next((out / "runs").iterdir()) / "bsa"
    before = (run_dir / "path.csv").read_bytes()
    with pytest.raises(ccpp.CcppError, match="is a run of a ccpp bench"):
        ccpp.run(room, "ba-star").save(run_dir)
    with pytest.raises(ccpp.CcppError, match="is a run of a ccpp bench"):
        ccpp.plan(room).save(run_dir)
    assert (run_dir / "path.csv").read_bytes() == before
