"""The Gymnasium wrapper."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

gymnasium = pytest.importorskip("gymnasium")

from gymnasium.utils.env_checker import check_env  # noqa: E402

from ccpp.gym import CoverageEnv  # noqa: E402


def test_check_env(room: Path) -> None:
    env = CoverageEnv(str(room), radius=0.15, max_steps=50)
    check_env(env, skip_render_check=True)


def test_episode(room: Path) -> None:
    env = CoverageEnv(str(room), radius=0.15, max_steps=40, render_mode="rgb_array")
    obs, info = env.reset(seed=3)
    assert env.observation_space.contains(obs)
    total = 0.0
    done = False
    steps = 0
    while not done:
        # Forward until bumping is avoided by turning left every 4 steps.
        obs, reward, terminated, truncated, info = env.step(0 if steps % 4 else 1)
        total += reward
        steps += 1
        done = terminated or truncated
    assert total > 0 and 0 < info["coverage"] <= 1
    img = env.render()
    assert img is not None and img.shape == (40, 60, 3)


def test_refuses_what_it_would_ignore(room: Path) -> None:
    # More than two turns was accepted, and then every turn action failed.
    for kw in (
        {"step_m": 0.0},
        {"step_m": -0.1},
        {"turn_rad": float("nan")},
        {"turn_rad": 0},
        {"turn_rad": 4 * math.pi + 0.1},
    ):
        with pytest.raises(ValueError, match=next(iter(kw))):
            CoverageEnv(str(room), **kw)
    # Two turns is the most, and a turn of it is taken.
    env = CoverageEnv(str(room), turn_rad=4 * math.pi, max_steps=5)
    env.reset(seed=1)
    env.step(1)
    # `radius=None` is the default robot, as for `ccpp.Env` (it was a bare TypeError).
    env = CoverageEnv(str(room), radius=None)
    assert env.step_m == 0.15
    env = CoverageEnv(str(room), max_steps=5)
    env.reset(seed=1, options={})
    with pytest.raises(ValueError, match="no options"):
        env.reset(seed=1, options={"start": (1.0, 1.0)})
    # Numbers and flags are typed as `ccpp.Env` types them: "0.3" and True were steps (True a
    # 1 m step), and "no" kept random starts and the known map on.
    import numpy as np

    for kw in (
        {"step_m": "0.3"},
        {"step_m": True},
        {"turn_rad": "1.5"},
        {"turn_rad": True},
        {"random_start": "no"},
        {"include_known": "no"},
        {"include_known": 0},
        {"turn_rad": None},
        {"step_m": np.array(True)},
    ):
        with pytest.raises(TypeError, match=next(iter(kw))):
            CoverageEnv(str(room), **kw)
    from fractions import Fraction

    env = CoverageEnv(str(room), step_m=np.float32(0.25), turn_rad=1, include_known=np.bool_(False))
    assert env.step_m == pytest.approx(0.25) and env.turn_rad == 1.0
    assert "known" not in env.observation_space.spaces
    env = CoverageEnv(str(room), step_m=np.array(0.25), turn_rad=Fraction(3, 2), random_start=np.array(False))
    assert env.step_m == 0.25 and env.turn_rad == 1.5 and env.random_start is False


def test_only_the_actions_of_the_space(room: Path) -> None:
    """`int(action)` took 1.7 for action 1, and True and "1" too."""
    import numpy as np

    env = CoverageEnv(str(room), max_steps=10)
    env.reset(seed=1)
    for bad in (1.7, True, "1", 3, -1, np.float64(1.0), np.array([1])):
        with pytest.raises(ValueError, match="action must be 0, 1 or 2"):
            env.step(bad)
    for good in (0, 1, 2, np.int64(1), np.array(2)):
        env.step(good)
