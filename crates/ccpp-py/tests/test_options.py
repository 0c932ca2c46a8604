"""Every keyword option changes what it should or is refused: never accepted and then dropped
(the command line's rules, one ``Scenario`` validation)."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

import ccpp

PID = {"exec": {"pid": {"dt_s": 0.1}}}


def cli(binary: str, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([binary, *args], capture_output=True, text=True, check=False)


def test_exec_keeps_or_refuses_the_planners_pid_settings(room: Path, ccpp_bin: str, tmp_path: Path) -> None:
    m = ccpp.load_map(room)
    base = ccpp.run(m, "bsa-bfs")
    own = ccpp.run(m, "bsa-bfs", options=PID)
    assert not np.array_equal(own.path, base.path), "bsa_bfs.exec.pid.dt_s changed nothing"
    # exec="pid" runs the planner's own PID settings (as `--exec pid --config`), whatever the
    # order of the keywords.
    for r in (ccpp.run(m, "bsa-bfs", exec="pid", options=PID), ccpp.run(m, "bsa-bfs", options=PID, exec="pid")):
        assert np.array_equal(r.path, own.path)
        assert json.loads(r.scenario_json)["sim"]["exec"]["pid"]["dt_s"] == 0.1
    # exec="ideal" would drop them: refused naming the option, as `--exec ideal --config` is.
    cfg = tmp_path / "pid.yaml"
    cfg.write_text("bsa_bfs: { exec: { pid: { dt_s: 0.1 } } }\n")
    p = cli(ccpp_bin, "run", "--map", str(room), "--planner", "bsa-bfs", "--exec", "ideal",
            "--config", str(cfg), "--out", str(tmp_path / "o"))
    assert p.returncode != 0 and "bsa_bfs.exec" in p.stderr
    with pytest.raises(ccpp.CcppError, match=r"ideal .*bsa_bfs\.exec; remove one of them"):
        ccpp.run(m, "bsa-bfs", exec="ideal", options=PID)
    with pytest.raises(ccpp.CcppError, match=r"rect_boustrophedon\.exec"):
        ccpp.run(m, "rect-boustrophedon", options=PID, exec="ideal")
    # A planner told to run ideally and exec="pid" disagree as well.
    with pytest.raises(ccpp.CcppError, match=r"bsa_bfs\.exec"):
        ccpp.run(m, "bsa-bfs", exec="pid", options={"exec": "ideal"})
    # Without settings of its own, the planner's default execution is replaced.
    ideal = ccpp.run(m, "bsa-bfs", exec="ideal")
    assert "tracking_error_mean_m" not in ideal.metrics or ideal.metrics["tracking_error_mean_m"] is None
    # A string only: the planner's own settings go in options=.
    with pytest.raises(ccpp.CcppError, match="exec must be"):
        ccpp.run(m, "bsa-bfs", exec={"pid": {}})


def test_a_keyword_and_the_same_key_in_options_must_agree(room: Path, ccpp_bin: str, tmp_path: Path) -> None:
    m = ccpp.load_map(room)
    for kw, opts in (({"smoothing": False}, {"smoothing": True}), ({"smoothing": True}, {"smoothing": False})):
        with pytest.raises(ccpp.CcppError, match=r"smoothing=.* and options\[\"smoothing\"\]=.* set the same option"):
            ccpp.run(m, "ba-star", **kw, options=opts)
        with pytest.raises(ccpp.CcppError, match="set the same option"):
            ccpp.run(m, "ba-star", options=opts, **kw)
    # Equal values are one value (as the CLI accepts a flag equal to the file's value).
    off = ccpp.run(m, "ba-star", smoothing=False)
    both = ccpp.run(m, "ba-star", smoothing=False, options={"smoothing": False})
    assert np.array_equal(both.path, off.path)
    # random-bounce's seed is its option `seed`: seed= and options={"seed": ...} likewise.
    with pytest.raises(ccpp.CcppError, match=r"seed=1 and options\[\"seed\"\]=2 set the same option"):
        ccpp.run(m, "random-bounce", seed=1, options={"seed": 2})
    assert np.array_equal(
        ccpp.run(m, "random-bounce", seed=2, options={"seed": 2}).path, ccpp.run(m, "random-bounce", seed=2).path
    )
    # ... and under odometry noise too: the option's seed seeds the noise as seed= does (the
    # noise was seeded 0 when the seed came from the options; hostile pass).
    by_kw = ccpp.run(m, "random-bounce", seed=7, odometry_noise=0.01)
    by_opt = ccpp.run(m, "random-bounce", options={"seed": 7}, odometry_noise=0.01)
    assert np.array_equal(by_kw.path, by_opt.path)
    assert json.loads(by_opt.scenario_json)["sim"]["exec"]["pid"]["noise"]["seed"] == 7
    # Seeds span the whole u64 range, as `--seed` does.
    big = ccpp.run(m, "random-bounce", seed=2**64 - 1)
    assert json.loads(big.scenario_json)["options"]["seed"] == 2**64 - 1
    # The CLI refuses the same clash.
    cfg = tmp_path / "rb.yaml"
    cfg.write_text("random_bounce: { seed: 2 }\n")
    p = cli(ccpp_bin, "run", "--map", str(room), "--planner", "random-bounce", "--seed", "1",
            "--config", str(cfg), "--out", str(tmp_path / "o"))
    assert p.returncode != 0 and "set the same option" in p.stderr


def test_plan_refuses_what_a_plan_would_drop(room: Path, ccpp_bin: str, tmp_path: Path) -> None:
    # `ccpp plan --planner rect-boustrophedon --tool-radius` is refused: its lanes follow width.
    p = cli(ccpp_bin, "plan", "--map", str(room), "--planner", "rect-boustrophedon", "--tool-radius", "0.1",
            "--out", str(tmp_path / "o"))
    assert p.returncode != 0 and "--tool-radius does not apply" in p.stderr
    with pytest.raises(ccpp.CcppError, match="tool_radius does not apply to rect-boustrophedon"):
        ccpp.plan(room, "rect-boustrophedon", tool_radius=0.1)
    # bcd's lanes follow the tool: there it applies.
    assert ccpp.plan(room, "bcd", tool_radius=0.1).export("csv") != ccpp.plan(room, "bcd").export("csv")
    # A radius under the rectangle's disk (0.2121 m for 0.3 x 0.3) changed nothing: refused, as
    # `ccpp plan --radius` is; above it, it changes the plan.
    rect = {"length_m": 0.3, "width_m": 0.3}
    with pytest.raises(ccpp.CcppError, match=r"radius 0.1 m changes nothing here.*0.2121 m"):
        ccpp.plan(room, "rect-boustrophedon", radius=0.1, **rect)
    plain = ccpp.plan(room, "rect-boustrophedon", **rect).export("csv")
    assert ccpp.plan(room, "rect-boustrophedon", radius=0.3, **rect).export("csv") != plain
    # The GeoJSON names the rectangle a rect-boustrophedon route was planned for (as `ccpp plan`).
    geo = json.loads(ccpp.plan(room, "rect-boustrophedon", length_m=0.5, width_m=0.3).export("geojson"))
    assert geo["features"][0]["properties"]["robot"]["footprint"] == {
        "shape": "rectangle", "length_m": 0.5, "width_m": 0.3, "clearance_radius_m": 0.5 * (0.5**2 + 0.3**2) ** 0.5,
    }
    assert "footprint" not in json.loads(ccpp.plan(room, "bcd").export("geojson"))["features"][0]["properties"]["robot"]
    # A start heading changes nothing a plan gives (`ccpp plan --start X,Y,THETA` is refused).
    p = cli(ccpp_bin, "plan", "--map", str(room), "--planner", "bcd", "--start", "1,1,1",
            "--out", str(tmp_path / "o"))
    assert p.returncode != 0 and "THETA" in p.stderr
    # Any heading, 0 included (it was taken and dropped where 1.0 was refused).
    for theta in (1.0, 0.0, 0, -0.0):
        with pytest.raises(ccpp.CcppError, match="start theta does not apply to plan"):
            ccpp.plan(room, "bcd", start=(1.0, 1.0, theta))
    p = cli(ccpp_bin, "plan", "--map", str(room), "--planner", "bcd", "--start", "1,1,0",
            "--out", str(tmp_path / "o"))
    assert p.returncode != 0 and "THETA" in p.stderr
    assert ccpp.plan(room, "bcd", start=(1.0, 1.0)).finished
    # A plan executes the steps ideally: an execution would be dropped.
    with pytest.raises(ccpp.CcppError, match=r"sim\.exec \(--exec, --odometry-noise; exec=, odometry_noise=\) does not apply to a plan"):
        ccpp.plan(room, "bcd", exec="pid")
    with pytest.raises(ccpp.CcppError, match=r"rect_boustrophedon\.exec does not apply to a plan"):
        ccpp.plan(room, "rect-boustrophedon", options=PID)
    cfg = tmp_path / "pid.yaml"
    cfg.write_text("rect_boustrophedon: { exec: { pid: { dt_s: 0.1 } } }\n")
    p = cli(ccpp_bin, "plan", "--map", str(room), "--planner", "rect-boustrophedon", "--config", str(cfg),
            "--out", str(tmp_path / "o"))
    assert p.returncode != 0 and "rect_boustrophedon.exec" in p.stderr


def test_bad_values_are_ccpp_errors_naming_the_option(room: Path) -> None:
    m = ccpp.load_map(room)
    for kw, name in (
        ({"max_memory_mb": -1}, "max_memory_mb"),
        ({"max_memory_mb": 1.5}, "max_memory_mb"),
        ({"max_steps": -3}, "max_steps"),
        ({"max_steps": 0}, "max_steps"),
        ({"max_memory_mb": 0}, "max_memory"),
        ({"tool_radius": "wide"}, "tool_radius"),
        ({"sensor_range": float("nan")}, "sensor_range"),
        ({"sensor_range": -1.0}, "sensor_range"),
        ({"tool_radius": float("inf")}, "tool radius"),
        ({"start": (float("nan"), 1.0)}, "start"),
        ({"start": (1.0,)}, "start"),
    ):
        with pytest.raises(ccpp.CcppError, match=name):
            ccpp.run(m, "bsa", **kw)
    with pytest.raises(ccpp.CcppError, match="seed"):
        ccpp.run(m, "random-bounce", seed=-1)
    with pytest.raises(ccpp.CcppError, match="options must be a dict"):
        ccpp.run(m, "bsa", options=[("side", "left")])


def test_name_is_the_name_every_output_reports(room: Path) -> None:
    r = ccpp.run(room, "bsa", name="box")
    assert r.metrics["map"] == "box"
    assert json.loads(r.scenario_json)["map"]["name"] == "box"
    p = ccpp.plan(room, "bcd", name="box")
    assert "box" in repr(p) and "box" in p.export("json")


def test_env_refuses_a_zero_episode_cap(room: Path) -> None:
    with pytest.raises(ccpp.CcppError, match="max_steps must be >= 1"):
        ccpp.Env(room, max_steps=0)
    env = ccpp.Env(room, max_steps=1)
    env.reset()
    assert env.step(("rotate", 0.1))[3] is True


def _same(a, b) -> bool:
    """Two runs' metrics, timing aside."""
    strip = lambda r: {k: v for k, v in r.metrics.items() if k != "wall_time_s"}  # noqa: E731
    return strip(a) == strip(b)


def test_none_is_the_default_of_every_optional_keyword(room: Path) -> None:
    m = ccpp.load_map(room)
    base = ccpp.run(m, "bsa")
    none = ccpp.run(
        m, None, None, tool_radius=None, start=None, sensor_range=None, max_memory_mb=None,
        max_steps=None, exec=None, options=None, name=None, area=None, keepout=None,
        smoothing=None,
    )
    assert none.metrics["planner"] == "ba-star"
    assert _same(ccpp.run(m, "bsa", radius=None, side=None, options=None), base)
    assert _same(ccpp.run(m, "random-bounce", seed=None, budget_m=None, max_steps=None),
                 ccpp.run(m, "random-bounce"))
    # A None beside the same key in options= is "not given": the options' value holds.
    three = ccpp.run(m, "random-bounce", seed=None, options={"seed": 3})
    assert _same(three, ccpp.run(m, "random-bounce", seed=3))
    assert not _same(three, ccpp.run(m, "random-bounce"))
    # A misspelt name is refused, None or not.
    with pytest.raises(ccpp.CcppError, match="sidee"):
        ccpp.run(m, "bsa", sidee=None)
    with pytest.raises(ccpp.CcppError, match="smoothing"):
        ccpp.run(m, "bsa", smoothing=None)  # a ba-star option, not bsa's
    assert "bcd" in repr(ccpp.plan(m, None, None, start=None))
    env = ccpp.Env(m, radius=None, tool_radius=None, sensor_range=None, start=None, exec=None,
                   max_steps=None, area=None, keepout=None)
    assert env.radius == 0.15
    assert ccpp._ccpp.bench_run(str(room), "bcd", None)[0]["robot_radius_m"] == 0.15


def test_headings_beyond_two_turns_and_huge_sensor_ranges(room: Path) -> None:
    m = ccpp.load_map(room)
    for bad in (1e300, 90.0, -13.0):
        with pytest.raises(ccpp.CcppError, match="more than two turns"):
            ccpp.run(m, "bsa", start=(1.0, 1.0, bad))
        with pytest.raises(ccpp.CcppError, match="more than two turns"):
            ccpp.load_map(room, origin=[0.0, 0.0, bad])
    ccpp.run(m, "bsa", start=(1.0, 1.0, -6.0))
    # Beyond twice the map's diagonal (3 x 2 m room) the sensor runs as that range.
    far = ccpp.run(m, "random-bounce", sensor_range=1e300)
    assert _same(far, ccpp.run(m, "random-bounce", sensor_range=8.0))
    assert ccpp.Env(m, sensor_range=1e300).sensor_range == pytest.approx(2 * (3.0**2 + 2.0**2) ** 0.5)


def test_the_work_area_and_rect_boustrophedons_lane_area_are_both_honoured(room: Path) -> None:
    # `area=` is the run's work area (virtual walls, as --area); options={"area": ...} is
    # rect-boustrophedon's lane rectangle (rect_boustrophedon.area in --config). Given
    # together, neither replaces the other: the run differs from each alone.
    m = ccpp.load_map(room)
    work = [0.3, 0.3, 2.0, 1.7]
    lanes = {"area": [1.0, 0.5, 2.7, 1.5]}
    both = ccpp.run(m, "rect-boustrophedon", area=work, options=lanes)
    assert not _same(both, ccpp.run(m, "rect-boustrophedon", area=work))
    assert not _same(both, ccpp.run(m, "rect-boustrophedon", options=lanes))


def test_exec_ideal_beside_pid_settings_at_their_defaults_is_refused(room: Path) -> None:
    # As `--exec ideal` beside `bsa_bfs.exec` in `--config`: the settings given would be read
    # and dropped, even at their defaults (they were accepted).
    with pytest.raises(ccpp.CcppError, match="drops the PID settings"):
        ccpp.run(room, "bsa-bfs", exec="ideal", options={"exec": {"pid": {}}})
    ccpp.run(room, "bsa-bfs", exec="ideal")


def test_odometry_noise_and_landmarks_are_the_cli_runs(shared_maps: Path, ccpp_bin: str, tmp_path: Path) -> None:
    """Python could not express a run with odometry noise or landmarks (`odometry_noise=` and
    `landmarks=` were unknown, and `seed=` was refused for every planner but random-bounce),
    so a CLI run.json had no Python equivalent. They are the flags' keywords now, through the
    same rules (`ccpp_io::execution`)."""
    maze = shared_maps / "teb_maze.yaml"
    tags = tmp_path / "tags.csv"
    tags.write_text("0,1,1\n1,9,1\n2,1,9\n3,9,9\n4,5,5\n")
    cases = [
        (["--odometry-noise", "0.02", "--seed", "1"], {"odometry_noise": 0.02, "seed": 1}),
        (["--odometry-noise", "0.02,0.01,0.1"], {"odometry_noise": (0.02, 0.01, 0.1)}),
        (
            ["--odometry-noise", "0.02", "--seed", "1", "--landmarks", str(tags)],
            {"odometry_noise": [0.02], "seed": 1, "landmarks": str(tags)},
        ),
    ]
    traces = []
    for k, (flags, kw) in enumerate(cases):
        out = tmp_path / f"cli{k}"
        p = cli(ccpp_bin, "run", "--map", str(maze), "--planner", "bcd", "--out", str(out), *flags)
        assert p.returncode == 0, p.stderr
        r = ccpp.run(maze, "bcd", **kw)
        r.save(tmp_path / f"py{k}")
        trace = (tmp_path / f"py{k}" / "trace.jsonl").read_text()
        assert trace == (out / "trace.jsonl").read_text(), flags
        assert json.loads(r.scenario_json)["sim"] == json.loads((out / "run.json").read_text())["sim"]
        traces.append(trace)
    assert len(set(traces)) == 3, "noise, drift or landmarks changed nothing"
    # Landmarks as a list are the file's.
    listed = ccpp.run(maze, "bcd", odometry_noise=0.02, seed=1, landmarks=[(0, 1, 1), (1, 9, 1), (2, 1, 9), (3, 9, 9), (4, 5, 5)])
    assert np.array_equal(listed.path, ccpp.run(maze, "bcd", **cases[2][1]).path)
    # Refused as the command line refuses them.
    for kw, needle in [
        ({"odometry_noise": 0}, "odometry_noise 0 draws no noise"),
        ({"odometry_noise": 1e-17}, "1e-17 is too small to change the motion"),
        ({"odometry_noise": (0.1, 0.1, 0.1, 0.1)}, "one to three finite numbers"),
        ({"odometry_noise": "0.1"}, "odometry_noise expects a number"),
        ({"odometry_noise": 0.1, "exec": "ideal"}, "needs PID execution, not exec ideal"),
        ({"seed": 3}, r"seed does not apply to bcd \(it applies to random-bounce and odometry_noise\)"),
        ({"landmarks": []}, "no landmark"),
        ({"landmarks": str(tmp_path / "none.csv")}, "none.csv"),
        # Without odometry noise the estimate is the true pose: nothing to correct.
        ({"exec": "pid", "landmarks": [(0, 1, 1)]}, "landmarks correct odometry drift"),
    ]:
        with pytest.raises(ccpp.CcppError, match=needle):
            ccpp.run(maze, "bcd", **kw)
    with pytest.raises(ccpp.CcppError, match="does not apply to a plan"):
        ccpp.plan(maze, "bcd", odometry_noise=0.02)
    with pytest.raises(ccpp.CcppError, match="the odometry noise setting of bsa-bfs .* set the same option"):
        ccpp.run(maze, "bsa-bfs", odometry_noise=0.02, options={"exec": {"pid": {"noise": None}}})


def test_nested_options_as_keywords_are_the_cli_flags(shared_maps: Path, ccpp_bin: str, tmp_path: Path) -> None:
    """`--smoothing off` and `--tile-side 0.4` set ba-star-extended's `ba_star` options, but
    `smoothing=False` and `tile_side_m=0.4` were "unknown field" for it in Python (only
    `ba_star={...}` worked). A keyword of exactly one nested section sets it there."""
    maze = shared_maps / "teb_maze.yaml"
    for flags, kw in (
        (["--smoothing", "off"], {"smoothing": False}),
        (["--tile-side", "0.4"], {"tile_side_m": 0.4}),
    ):
        out = tmp_path / flags[0].strip("-")
        p = cli(ccpp_bin, "run", "--map", str(maze), "--planner", "ba-star-extended", "--out", str(out), *flags)
        assert p.returncode == 0, p.stderr
        r = ccpp.run(maze, "ba-star-extended", **kw)
        assert json.loads(r.scenario_json)["options"] == json.loads((out / "run.json").read_text())["options"]
        nested = ccpp.run(maze, "ba-star-extended", ba_star=kw)
        assert np.array_equal(r.path, nested.path)
    # Beside the same option in options=, one value, as a flag beside --config.
    with pytest.raises(ccpp.CcppError, match=r"smoothing=False and options\[\"ba_star\"\]\[\"smoothing\"\]=True"):
        ccpp.run(maze, "ba-star-extended", smoothing=False, options={"ba_star": {"smoothing": True}})
    # Merged with other options of the same section.
    both = ccpp.run(maze, "ba-star-extended", smoothing=False, options={"ba_star": {"tile_side_m": 0.4}})
    assert json.loads(both.scenario_json)["options"]["ba_star"]["smoothing"] is False
    assert json.loads(both.scenario_json)["options"]["ba_star"]["tile_side_m"] == 0.4
    # An extension option too, and None as its default.
    yielded = ccpp.run(maze, "ba-star-extended", min_yield=0.2)
    assert json.loads(yielded.scenario_json)["options"]["extension"]["min_yield"] == 0.2
    ccpp.run(maze, "ba-star-extended", smoothing=None)
    with pytest.raises(ccpp.CcppError, match="unknown field"):
        ccpp.run(maze, "ba-star-extended", pid={"dt_s": 0.1})  # inside exec: not a keyword


def test_warnings_are_the_cli_warnings(shared_maps: Path, ccpp_bin: str, tmp_path: Path) -> None:
    """A run that ended `done` after its PID motions were cut short, or after drifting into
    walls, said so only in a trace note (Python) where `ccpp run` warns on stderr."""
    maze = shared_maps / "teb_maze.yaml"
    cut = {"exec": {"pid": {"max_steps_per_motion": 100}}}
    still = {"clearance_margin_m": 5}
    cases = [
        ({"odometry_noise": 0.02, "seed": 1}, ["--odometry-noise", "0.02", "--seed", "1"], "bcd", None),
        ({"options": cut}, ["--config", str(tmp_path / "cut.yaml")], "bsa-bfs", "bsa_bfs: { exec: { pid: { max_steps_per_motion: 100 } } }\n"),
        # A run that never moves, and a tool narrower than half a pixel (0.05 m map).
        ({"options": still}, ["--config", str(tmp_path / "cut.yaml")], "bsa-bfs", "bsa_bfs: { clearance_margin_m: 5 }\n"),
        ({"radius": 0.02}, ["--radius", "0.02"], "bsa", None),
    ]
    for kw, flags, planner, cfg in cases:
        if cfg:
            (tmp_path / "cut.yaml").write_text(cfg)
        r = ccpp.run(maze, planner, **kw)
        assert r.stop == "done" and r.warnings, planner
        p = cli(ccpp_bin, "run", "--map", str(maze), "--planner", planner, "--out", str(tmp_path / planner), *flags)
        assert p.returncode == 0, p.stderr
        cli_warnings = [line.removeprefix("warning: ") for line in p.stderr.splitlines() if line.startswith("warning: ")]
        assert r.warnings == cli_warnings
    assert ccpp.run(maze, "bcd").warnings == []
    # A start whose free area reaches the map's border (the robot may be outside the
    # building): `ccpp run` warned, Python's list left it out.
    # (nobleo_grid: its floor reaches the image's edge; nav2_depot's free pixels only leak
    # through gaps narrower than the robot, and it is no longer warned about)
    depot = shared_maps / "nobleo_grid.yaml"
    r = ccpp.run(depot, "bsa")
    assert any("reaches the map's border" in w for w in r.warnings), r.warnings
    p = cli(ccpp_bin, "run", "--map", str(depot), "--planner", "bsa", "--out", str(tmp_path / "depot"))
    assert p.returncode == 0, p.stderr
    assert r.warnings == [line.removeprefix("warning: ") for line in p.stderr.splitlines() if line.startswith("warning: ")]


def test_load_map_thresholds_and_georef_change_the_map(tmp_path: Path) -> None:
    """`occupied_thresh=`, `free_thresh=` and `georef=` of `load_map` had no test showing they
    change the map (hostile pass)."""
    w, h = 20, 10
    pix = bytearray()
    for y in range(h):
        for x in range(w):
            wall = x in (0, w - 1) or y in (0, h - 1)
            pix.append(0 if wall else (128 if x == 10 else 254))
    img = tmp_path / "grey.pgm"
    img.write_bytes(f"P5\n{w} {h}\n255\n".encode() + bytes(pix))
    plain = ccpp.load_map(img, resolution=0.05)
    grey = plain.occupancy[1:-1, 10]
    # p = (255 - 128) / 255 = 0.498: unknown between the defaults 0.196 and 0.65.
    assert (grey == 2).all()
    assert (ccpp.load_map(img, resolution=0.05, occupied_thresh=0.4).occupancy[1:-1, 10] == 1).all()
    assert (ccpp.load_map(img, resolution=0.05, free_thresh=0.55).occupancy[1:-1, 10] == 0).all()
    # A georeference of twice the scale: 0.1 m a pixel, the image's corner at (100, 200).
    g = tmp_path / "g.csv"
    g.write_text("px,py,wx,wy\n0,10,100,200\n20,10,102,200\n0,0,100,201\n")
    geo = ccpp.load_map(img, georef=g)
    assert geo.resolution == pytest.approx(0.1)
    assert geo.origin[:2] == pytest.approx((100.0, 200.0))
    assert np.array_equal(geo.occupancy, plain.occupancy)


def test_load_map_placement_stands_in_for_a_yamls_missing_fields(tmp_path: Path) -> None:
    """`resolution=` and `origin=` stand in for a map YAML without them: it was refused as
    lacking the field with the override given (hostile pass)."""
    w, h = 20, 10
    pix = bytes(0 if x in (0, w - 1) or y in (0, h - 1) else 254 for y in range(h) for x in range(w))
    (tmp_path / "m.pgm").write_bytes(f"P5\n{w} {h}\n255\n".encode() + pix)
    y = tmp_path / "m.yaml"
    y.write_text("image: m.pgm\n")
    with pytest.raises(ccpp.CcppError, match="lacks the required field `resolution`"):
        ccpp.load_map(y)
    with pytest.raises(ccpp.CcppError, match="lacks the required field `origin`"):
        ccpp.load_map(y, resolution=0.1)
    m = ccpp.load_map(y, resolution=0.1, origin=(3.0, 4.0, 0.0))
    assert m.resolution == pytest.approx(0.1)
    assert m.origin == pytest.approx((3.0, 4.0, 0.0))
    assert ccpp.run(m, "ba-star").metrics["effective_coverage"] > 0.5


def test_a_maps_setting_given_to_run_or_plan_points_to_load_map(room: Path) -> None:
    """`run(m, resolution=0.1)` was refused as an unknown ba_star field without a word of
    `load_map`, where it belongs (hostile pass)."""
    for key, value in [("resolution", 0.1), ("origin", (1.0, 2.0, 0.0)), ("inflate", 0.1),
                       ("occupied_thresh", 0.5), ("free_thresh", 0.1), ("georef", "g.csv")]:
        for call in (lambda **kw: ccpp.run(room, "ba-star", **kw), lambda **kw: ccpp.plan(room, "bcd", **kw)):
            with pytest.raises(ccpp.CcppError, match=rf"^{key} is a setting of the map, not of the run: "
                               rf"load the map with ccpp.load_map\(path, {key}=\.\.\.\) and pass that map$"):
                call(**{key: value})


def test_a_bcd_margin_no_transfer_can_keep_is_a_plan_and_run_warning(tmp_path: Path) -> None:
    # Three rooms in a row joined by corridors 0.4 m wide, the start in the middle one: one
    # corridor is driven again as a transfer, closer to its walls than margin_px 3 asks. It
    # fell back to the plain clearance without a word.
    w, h = 182, 42
    pix = bytearray()
    for y in range(h):
        for x in range(w):
            wall = x in (0, w - 1) or y in (0, h - 1)
            wall |= (41 <= x < 71 or 111 <= x < 141) and not 17 <= y < 25
            pix.append(0 if wall else 254)
    img = tmp_path / "three_rooms.pgm"
    img.write_bytes(f"P5\n{w} {h}\n255\n".encode() + bytes(pix))
    said = ccpp.plan(img, "bcd", start=(4.5, 1.0), margin_px=3).warnings
    assert len(said) == 1 and said[0].startswith("bcd: margin_px 3 was not kept on "), said
    assert ccpp.plan(img, "bcd", start=(4.5, 1.0)).warnings == []
    ran = ccpp.run(img, "bcd", start=(4.5, 1.0), margin_px=3).warnings
    assert any(w.startswith("bcd: margin_px 3 was not kept on ") for w in ran), ran


def test_another_planners_option_is_said_as_the_cli_says_it(room: Path, ccpp_bin: str, tmp_path: Path) -> None:
    """`side="left"` for ba-star was serde's "unknown field `side`, expected one of ..." while
    `ccpp run --planner ba-star --side left` says the option belongs to bsa and bsa-extended
    (docs review). Both say it now; an option of no planner is still "unknown field"."""
    p = cli(ccpp_bin, "run", "--map", str(room), "--planner", "ba-star", "--side", "left", "--out", str(tmp_path / "o"))
    assert p.returncode == 1 and "does not apply to ba-star (it applies to bsa, bsa-extended)" in p.stderr, p.stderr
    for kw in ({"side": "left"}, {"options": {"side": "left"}}):
        with pytest.raises(ccpp.CcppError, match=r"^side does not apply to ba-star \(it applies to bsa, bsa-extended\)$"):
            ccpp.run(room, "ba-star", **kw)
    # bcd's option for a tile planner; ba-star-extended's nested ba_star option for bsa
    with pytest.raises(ccpp.CcppError, match=r"turn_cost_m does not apply to bsa \(it applies to bcd"):
        ccpp.run(room, "bsa", turn_cost_m=0.5)
    with pytest.raises(ccpp.CcppError, match=r"smoothing does not apply to bsa \(it applies to ba-star, ba-star-extended\)"):
        ccpp.run(room, "bsa", smoothing=False)
    with pytest.raises(ccpp.CcppError, match="unknown field"):
        ccpp.run(room, "ba-star", no_such_option=1)
