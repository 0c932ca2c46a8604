"""Shared fixtures: the team's maps, the `ccpp` binary, a generated empty room."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[3]
SHARED_MAPS = REPO.parent / "shared" / "maps"
#: Three small shared maps the Python results are compared on against the CLI.
COMPARE_MAPS = ["teb_maze", "teb_corridor", "nobleo_grid"]


@pytest.fixture(scope="session")
def shared_maps() -> Path:
    if not SHARED_MAPS.is_dir():
        pytest.skip(f"{SHARED_MAPS} absent")
    return SHARED_MAPS


@pytest.fixture(scope="session")
def ccpp_bin() -> str:
    """The command line to compare with: $CCPP_BIN, else target/{release,debug}/ccpp, else PATH."""
    candidates = [os.environ.get("CCPP_BIN")]
    candidates += [str(REPO / "target" / p / "ccpp") for p in ("release", "debug")]
    candidates.append(shutil.which("ccpp"))
    for c in candidates:
        if c and Path(c).is_file() and os.access(c, os.X_OK):
            return c
    if os.environ.get("CI"):
        pytest.fail("no ccpp binary (set CCPP_BIN or build it with cargo build -p ccpp-cli)")
    pytest.skip("no ccpp binary (set CCPP_BIN or build it with cargo build -p ccpp-cli)")


def write_room(folder: Path, width: int = 60, height: int = 40, resolution: float = 0.05) -> Path:
    """An empty rectangular room: a one-pixel wall around free floor, as map_server files."""
    pixels = bytearray()
    for row in range(height):
        for col in range(width):
            wall = row in (0, height - 1) or col in (0, width - 1)
            pixels.append(0 if wall else 254)
    pgm = folder / "room.pgm"
    pgm.write_bytes(f"P5\n{width} {height}\n255\n".encode() + bytes(pixels))
    yaml = folder / "room.yaml"
    yaml.write_text(
        f"image: room.pgm\nresolution: {resolution}\norigin: [0.0, 0.0, 0.0]\n"
        "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    return yaml


@pytest.fixture()
def room(tmp_path: Path) -> Path:
    return write_room(tmp_path)
