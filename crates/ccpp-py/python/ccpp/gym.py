"""A Gymnasium environment on :class:`ccpp.Env` (needs ``gymnasium``:
``pip install 'ccpp-planner[gym]'``).

Actions (``Discrete(3)``): 0 drive forward ``step_m`` metres, 1 turn left ``turn_rad``, 2 turn
right ``turn_rad``. Observations (``Dict``): ``pose`` (x, y, theta as float32), ``scan`` (the
square window of image pixels around the robot, 0 free / 1 occupied / 2 unknown or out of
range) and, with ``include_known``, ``known`` (the map seen so far, same codes). The reward is
the newly swept accessible floor in m²; an episode terminates on a collision or at full coverage
and is truncated after ``max_steps`` actions (``None``: never).
"""

from __future__ import annotations

import math
from typing import Any

try:
    import gymnasium as gym
    from gymnasium import spaces
except ImportError as e:  # pragma: no cover - exercised only without gymnasium
    raise ImportError(
        "ccpp.gym needs gymnasium: pip install 'ccpp-planner[gym]' (or pip install gymnasium)"
    ) from e

import numpy as np

from . import _ccpp

__all__ = ["CoverageEnv"]


def _is_bool(v: Any) -> bool:
    return isinstance(v, (bool, np.bool_)) or (isinstance(v, np.ndarray) and v.shape == () and v.dtype.kind == "b")


def _number(name: str, v: Any) -> None:
    """A number as the package takes one: anything with ``__float__`` (numpy scalars, 0-d
    arrays, ``Fraction``) but a bool, and not text."""
    if _is_bool(v) or isinstance(v, (str, bytes)) or not hasattr(v, "__float__"):
        raise TypeError(f"{name} must be a number, not {type(v).__name__}")


def _flag(name: str, v: Any) -> None:
    if not _is_bool(v):
        raise TypeError(f"{name} must be a bool, not {type(v).__name__}")


class CoverageEnv(gym.Env):  # type: ignore[misc]
    """Coverage of one map by a round robot, one discrete action at a time."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(
        self,
        map: Any,
        radius: float | None = 0.15,
        tool_radius: float | None = None,
        sensor_range: float | None = None,
        step_m: float | None = None,
        turn_rad: float = math.pi / 2,
        max_steps: int | None = 1000,
        random_start: bool = True,
        include_known: bool = True,
        render_mode: str | None = None,
    ) -> None:
        # Numbers are numbers and flags are flags, checked before the map is read: `float()`
        # took "0.3" and True (a 1 m step), and "no" was a true flag.
        if step_m is not None:
            _number("step_m", step_m)
        _number("turn_rad", turn_rad)
        _flag("random_start", random_start)
        _flag("include_known", include_known)
        self._env = _ccpp.Env(
            map,
            radius=radius,
            tool_radius=tool_radius,
            sensor_range=sensor_range,
            max_steps=max_steps,
        )
        # `radius=None` is the default robot, as for `ccpp.Env`.
        self.step_m = float(step_m if step_m is not None else self._env.radius)
        self.turn_rad = float(turn_rad)
        for name, v in (("step_m", self.step_m), ("turn_rad", self.turn_rad)):
            # 0 would make the action a no-op, a negative value reverse it, NaN fail each step.
            if not (math.isfinite(v) and v > 0):
                raise ValueError(f"{name} must be a finite number > 0, got {v}")
        # The simulator refuses a rotation of more than two turns: each turn action would fail.
        if self.turn_rad > 4 * math.pi:
            raise ValueError(f"turn_rad must be at most two turns (4 pi rad), got {self.turn_rad}")
        self.random_start = bool(random_start)
        self.include_known = bool(include_known)
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode must be None or 'rgb_array', got {render_mode!r}")
        self.render_mode = render_mode
        m = self._env.map
        self._occupancy = m.occupancy
        ox, oy, yaw = m.origin
        wm, hm = m.size_m
        corners = [
            (ox + u * math.cos(yaw) - v * math.sin(yaw), oy + u * math.sin(yaw) + v * math.cos(yaw))
            for u, v in ((0, 0), (wm, 0), (0, hm), (wm, hm))
        ]
        xs, ys = zip(*corners)
        self._low = np.array([min(xs), min(ys), -math.pi], dtype=np.float32)
        self._high = np.array([max(xs), max(ys), math.pi], dtype=np.float32)
        side = self._env.scan_side
        obs: dict[str, spaces.Space] = {
            "pose": spaces.Box(self._low, self._high, dtype=np.float32),
            "scan": spaces.Box(0, 2, shape=(side, side), dtype=np.uint8),
        }
        if include_known:
            obs["known"] = spaces.Box(0, 2, shape=(m.height, m.width), dtype=np.uint8)
        self.observation_space = spaces.Dict(obs)
        self.action_space = spaces.Discrete(3)

    def _obs(self, o: dict[str, Any]) -> dict[str, np.ndarray]:
        pose = np.clip(np.asarray(o["pose"], dtype=np.float32), self._low, self._high)
        out = {"pose": pose, "scan": o["scan"]}
        if self.include_known:
            out["known"] = o["known"]
        return out

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        if options:
            # Nothing here reads them: refused rather than ignored.
            raise ValueError(f"CoverageEnv.reset takes no options, got {options!r}")
        super().reset(seed=seed)
        start_seed = int(self.np_random.integers(0, 2**63)) if self.random_start else None
        o, info = self._env.reset(start_seed)
        return self._obs(o), info

    def step(
        self, action: Any
    ) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        # Only the actions of `Discrete(3)`: `int()` took 1.7, True and "1" as actions.
        integral = isinstance(action, (int, np.integer)) or (
            isinstance(action, np.ndarray) and action.shape == () and action.dtype.kind in "iu"
        )
        if not integral or isinstance(action, (bool, np.bool_)):
            raise ValueError(f"action must be 0, 1 or 2, got {action!r}")
        a = int(action)
        if a == 0:
            act: tuple[Any, ...] = ("translate", self.step_m)
        elif a == 1:
            act = ("rotate", self.turn_rad)
        elif a == 2:
            act = ("rotate", -self.turn_rad)
        else:
            raise ValueError(f"action must be 0, 1 or 2, got {action!r}")
        o, reward, terminated, truncated, info = self._env.step(act)
        return self._obs(o), float(reward), bool(terminated), bool(truncated), info

    def render(self) -> np.ndarray | None:
        """An RGB picture in image layout: obstacles near black, unknown grey, floor white,
        swept floor light blue."""
        if self.render_mode != "rgb_array":
            return None
        occ = self._occupancy
        img = np.full(occ.shape + (3,), 255, dtype=np.uint8)
        img[occ == 1] = (20, 20, 20)
        img[occ == 2] = (128, 128, 128)
        img[self._env.swept & (occ == 0)] = (150, 190, 255)
        return img
