"""Zones (area / keep-out) and path exports from Python, against the command line."""

from __future__ import annotations

import csv
import io
import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

import ccpp

AREA = [0.3, 0.3, 2.5, 1.7]
KEEPOUT = [1.0, 0.8, 1.4, 1.2]
FORMATS = ["csv", "json", "nav-path", "geojson"]
FILES = {"csv": "waypoints.csv", "json": "waypoints.json", "nav-path": "nav_path.yaml", "geojson": "path.geojson"}


def cli(binary: str, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([binary, *args], capture_output=True, text=True, check=False)


def rect(r: list[float]) -> str:
    return ",".join(str(v) for v in r)


def csv_rows(text: str) -> np.ndarray:
    rows = list(csv.DictReader(io.StringIO(text)))
    return np.array([[float(r["x"]), float(r["y"]), float(r["theta"])] for r in rows])


def test_run_with_zones_and_exports_equals_the_cli(room: Path, ccpp_bin: str, tmp_path: Path) -> None:
    out = tmp_path / "cli"
    args = ["run", "--map", str(room), "--planner", "bcd", "--area", rect(AREA), "--keepout", rect(KEEPOUT)]
    for f in FORMATS:
        args += ["--export", f]
    p = cli(ccpp_bin, *args, "--out", str(out), "--json")
    assert p.returncode == 0, p.stderr
    expected = json.loads(p.stdout)
    r = ccpp.run(room, "bcd", area=AREA, keepout=KEEPOUT)
    m = dict(r.metrics)
    m.pop("wall_time_s")
    expected.pop("wall_time_s")
    assert m == expected
    assert m["keepout_violations"] == 0
    # The zones change the run: less floor to cover than without them.
    plain = ccpp.run(room, "bcd")
    assert r.accessible.sum() < plain.accessible.sum()
    # The same export files as `--export`.
    py_out = tmp_path / "py"
    r.save(py_out, export=FORMATS)
    for f in ("csv", "json", "nav-path"):
        name = FILES[f]
        assert (py_out / name).read_text() == (out / name).read_text(), name
        assert r.export(f) == (out / name).read_text(), name
    # path.geojson's metrics leave the wall time out: the same bytes.
    assert (py_out / "path.geojson").read_bytes() == (out / "path.geojson").read_bytes()
    kinds = [f["properties"].get("kind") for f in json.loads(r.export("geojson"))["features"]]
    assert "area" in kinds and "keepout" in kinds
    # Waypoints: the CSV's rows; a coarser tolerance merges more.
    w = r.waypoints()
    assert w.shape[1] == 3 and np.array_equal(w, csv_rows(r.export("csv")))
    assert len(r.waypoints(tolerance_m=0.05)) <= len(w)
    # None is the default, as for the other keywords (it raised TypeError), and help() shows
    # the default's value (it showed Ellipsis).
    assert np.array_equal(r.waypoints(None), w)
    assert "tolerance_m=0.001" in (type(r).waypoints.__text_signature__ or "")
    # Without `export`, save writes no export file (as `ccpp run` without --export).
    bare = tmp_path / "bare"
    r.save(bare)
    assert not (bare / "waypoints.csv").exists() and (bare / "path.csv").is_file()


def test_waypoints_tolerance_merges_a_drifting_route(room: Path) -> None:
    """`waypoints(tolerance_m=)` was checked only with `<=`, which holds if the tolerance is
    ignored (kwargs pass): under heading drift the driven route bends between turns, and a
    finer tolerance keeps more of its poses, a coarser one fewer."""
    r = ccpp.run(room, "ba-star-extended", odometry_noise=(0.02, 0.02, 0.01), seed=1)
    fine, default, coarse = (len(r.waypoints(tolerance_m=t)) for t in (1e-6, None, 0.05))
    assert fine > 10 * default, (fine, default)
    assert default > coarse, (default, coarse)
    # Exactly straight moves (ideal execution) have nothing to merge at any tolerance.
    ideal = ccpp.run(room, "ba-star-extended")
    assert len({len(ideal.waypoints(tolerance_m=t)) for t in (1e-6, None, 0.05, 1e9)}) == 1


def test_export_refuses_unknown_formats_and_tolerances(room: Path) -> None:
    r = ccpp.run(room, "bcd")
    with pytest.raises(ccpp.CcppError, match="unknown export format"):
        r.export("kml")
    with pytest.raises(ccpp.CcppError, match="unknown export format"):
        r.save("unused", export=["csv", "shp"])
    with pytest.raises(ccpp.CcppError, match="tolerance_m"):
        r.waypoints(tolerance_m=-1.0)


def test_plan_equals_cli_plan(room: Path, ccpp_bin: str, tmp_path: Path) -> None:
    out = tmp_path / "cli"
    args = ["plan", "--map", str(room), "--planner", "bcd", "--keepout", rect(KEEPOUT)]
    p = cli(ccpp_bin, *args, "--out", str(out))
    assert p.returncode == 0, p.stderr
    plan = ccpp.plan(room, "bcd", keepout=KEEPOUT)
    assert plan.finished and plan.length_m > 0
    py_out = tmp_path / "py"
    plan.save(py_out)
    # Default files as `ccpp plan`: waypoints.csv and nav_path.yaml, byte for byte.
    assert sorted(x.name for x in py_out.iterdir()) == [".ccpp", "nav_path.yaml", "waypoints.csv"]
    for name in ("waypoints.csv", "nav_path.yaml"):
        assert (py_out / name).read_text() == (out / name).read_text(), name
    assert np.array_equal(plan.waypoints, csv_rows(plan.export("csv")))
    # The keep-out changes the plan.
    assert plan.export("csv") != ccpp.plan(room, "bcd").export("csv")
    with pytest.raises(ccpp.CcppError, match="online planner"):
        ccpp.plan(room, "ba-star")
    with pytest.raises(ccpp.CcppError, match="sensor_range does not apply to bcd"):
        ccpp.plan(room, "bcd", sensor_range=1.0)
    with pytest.raises(ccpp.CcppError, match=r"smoothing does not apply to bcd \(it applies to ba-star, ba-star-extended\)"):
        ccpp.plan(room, "bcd", smoothing=False)


def test_env_knows_its_zones(room: Path) -> None:
    plain = ccpp.Env(room, radius=0.15, sensor_range=0.6)
    env = ccpp.Env(room, radius=0.15, sensor_range=0.6, area=AREA, keepout=KEEPOUT, start=(0.6, 1.0, 0.0))
    plain.reset()
    obs, info = env.reset()
    assert env.accessible.sum() < plain.accessible.sum()
    # The keep-out's pixels in sensor range read as occupied (virtual walls).
    m = env.map
    col, row = 22, 19  # pixel centre (1.125, 1.025): inside the keep-out, 0.525 m ahead
    assert m.pixel_center(col, row) == pytest.approx((1.125, 1.025))
    # Outside the image: IndexError (a row past the last one panicked with an overflow).
    h, w = m.occupancy.shape
    for c, r in [(0, h), (w, 0), (0, 10**6)]:
        with pytest.raises(IndexError, match="outside the map"):
            m.pixel_center(c, r)
    assert m.occupancy[row, col] == 0 and obs["known"][row, col] == 1
    assert env.metrics()["keepout_violations"] == 0
    # A virtual wall does not stop the robot: driving into the keep-out is a violation, not a
    # collision.
    obs, reward, terminated, truncated, info = env.step(("translate", 0.6))
    assert not info["collision"]
    metrics = env.metrics()
    assert metrics["keepout_violations"] == 1 and metrics["collisions"] == 0
    # Seeded starts are inside the area and outside the keep-out (an Env without start=: with
    # one, a seed is refused).
    env = ccpp.Env(room, radius=0.15, sensor_range=0.6, area=AREA, keepout=KEEPOUT)
    for seed in range(5):
        obs, _ = env.reset(seed=seed)
        x, y, _ = obs["pose"]
        assert AREA[0] < x < AREA[2] and AREA[1] < y < AREA[3]
        assert not (KEEPOUT[0] - 0.15 < x < KEEPOUT[2] + 0.15 and KEEPOUT[1] - 0.15 < y < KEEPOUT[3] + 0.15)


def test_env_drives_into_the_area_and_refuses_bad_zones(room: Path) -> None:
    env = ccpp.Env(room, radius=0.15, area=[1.5, 0.3, 2.8, 1.7], start=(0.4, 1.0, 0.0))
    obs, info = env.reset()
    assert obs["pose"][0] >= 1.5 + 0.15 - 1e-9
    assert env.metrics()["path_length_m"] > 0.9
    with pytest.raises(ccpp.CcppError, match="keepout rectangle 1,1,0.5,0.5"):
        ccpp.Env(room, keepout=[1.0, 1.0, 0.5, 0.5])
    with pytest.raises(ccpp.CcppError, match="keep-out zone"):
        ccpp.Env(room, keepout=KEEPOUT, start=(1.2, 1.0, 0.0))
    with pytest.raises(ccpp.CcppError, match="keepout"):
        ccpp.Env(room, keepout=str(room.parent / "missing.geojson"))


def test_zone_and_seed_arguments_take_paths_and_numpy(room: Path, tmp_path: Path) -> None:
    # A pathlib.Path keep-out, a numpy area and a numpy seed were refused ("cannot use
    # PosixPath as an option value", "cannot use ndarray", "expected u64"), though maps and
    # starts take them; each gives the same run as its plain form.
    ko = tmp_path / "ko.yaml"
    ko.write_text("- [1.0, 0.8]\n- [1.4, 0.8]\n- [1.4, 1.2]\n- [1.0, 1.2]\n")
    a = ccpp.run(room, "bcd", area=AREA, keepout=str(ko))
    b = ccpp.run(room, "bcd", area=np.array(AREA), keepout=ko)
    assert a.metrics["path_length_m"] == b.metrics["path_length_m"]
    c = ccpp.run(room, "random-bounce", seed=np.int64(3))
    d = ccpp.run(room, "random-bounce", seed=3)
    assert c.metrics["path_length_m"] == d.metrics["path_length_m"]
    # A malformed zone says what a zone may be (not serde's "untagged enum ZoneSpec").
    with pytest.raises(ccpp.CcppError, match=r"area must be a file name, \[x0, y0, x1, y1\]"):
        ccpp.run(room, "bcd", area=[0, 0, 1])
    with pytest.raises(ccpp.CcppError, match="keepout must be a zone"):
        ccpp.run(room, "bcd", keepout=[0, 0, 1])
    # A value whose repr spans lines (numpy's 2-D arrays) is shown on one line, not with
    # `\u{a}` escapes.
    with pytest.raises(ccpp.CcppError, match=r"got array\(\[\[0\., 0\.\], \[0\., 0\.\]\]\)$"):
        ccpp.run(room, "bcd", area=np.zeros((2, 2)))


def test_a_runs_start_is_where_the_robot_was_placed(shared_maps: Path) -> None:
    # With a start outside the area, RunResult.start was where the drive to the area ends:
    # neither the path's first pose nor run.json's start.
    r = ccpp.run(shared_maps / "teb_maze.yaml", "bcd", area=[0, 0, 5, 5], start=(8, 8))
    assert r.start == (8.0, 8.0, 0.0)
    assert tuple(r.path[0]) == r.start
    assert json.loads(r.scenario_json)["start"] == [8.0, 8.0, 0.0]


def said(stderr: str, kind: str) -> list[str]:
    return [line[len(kind) + 2 :] for line in stderr.splitlines() if line.startswith(f"{kind}: ")]


def test_notes_and_warnings_are_the_clis(shared_maps: Path, ccpp_bin: str, tmp_path: Path) -> None:
    # A start outside the area: `ccpp run` and `ccpp plan` say the drive to the area as a note,
    # which Python kept to itself (RunResult and PlanResult had no notes).
    maze = shared_maps / "teb_maze.yaml"
    p = cli(ccpp_bin, "run", "--map", str(maze), "--planner", "bcd", "--area", "0,0,5,5", "--start", "8,8", "--out", str(tmp_path / "r"))
    assert p.returncode == 0, p.stderr
    r = ccpp.run(maze, "bcd", area=[0, 0, 5, 5], start=(8, 8))
    assert r.notes == said(p.stderr, "note") and len(r.notes) == 1, p.stderr
    assert r.notes[0].startswith("the start is outside the area: the robot first drives")
    p = cli(ccpp_bin, "plan", "--map", str(maze), "--planner", "bcd", "--area", "0,0,5,5", "--start", "8,8", "--out", str(tmp_path / "p"))
    assert p.returncode == 0, p.stderr
    plan = ccpp.plan(maze, area=[0, 0, 5, 5], start=(8, 8))
    assert plan.notes == said(p.stderr, "note") == r.notes
    assert ccpp.run(maze, "bcd").notes == [] and ccpp.plan(maze).notes == []
    # `ccpp plan`'s warning of a start whose free area reaches the map's border is a
    # PlanResult warning too (Python's plan had only the planner's own).
    # (nobleo_grid: its floor reaches the image's edge; nav2_depot's free pixels only leak
    # through gaps narrower than the robot, and it is no longer warned about)
    depot = shared_maps / "nobleo_grid.yaml"
    p = cli(ccpp_bin, "plan", "--map", str(depot), "--planner", "bcd", "--out", str(tmp_path / "d"))
    assert p.returncode == 0, p.stderr
    warned = said(p.stderr, "warning")
    assert any("reaches the map's border" in w for w in warned), p.stderr
    assert ccpp.plan(depot).warnings == warned
