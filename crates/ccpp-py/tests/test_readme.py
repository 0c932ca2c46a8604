"""The README's Python blocks run as written (from a folder beside `shared/`, as the README's
relative map paths assume): in order, in one namespace, and a block that starts a Dask cluster
as a script of its own (its workers import the script again, as a user's would)."""

from __future__ import annotations

import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import REPO, SHARED_MAPS


def readme_blocks() -> list[str]:
    text = (REPO / "README.md").read_text()
    return re.findall(r"```python\n(.*?)```", text, re.S)


def test_the_readme_python_blocks_run_as_written(tmp_path: Path) -> None:
    if not SHARED_MAPS.is_dir():
        pytest.skip(f"{SHARED_MAPS} absent")
    blocks = readme_blocks()
    # The library tour, zones and exports, the step API, the cluster sweep.
    assert len(blocks) >= 4, f"README has {len(blocks)} Python blocks"
    (tmp_path / "shared").symlink_to(SHARED_MAPS.parent)
    work = tmp_path / "work"
    work.mkdir()
    here = os.getcwd()
    os.chdir(work)
    try:
        namespace: dict = {"__name__": "readme"}
        for k, block in enumerate(blocks):
            if "distributed" in block:
                if importlib.util.find_spec("distributed") is None:
                    # The cluster block needs the sweep extra (`pip install '.[sweep]'`).
                    print(f"README block {k} not run: distributed is not installed")
                    continue
                script = work / f"block{k}.py"
                script.write_text(block)
                out = subprocess.run(
                    [sys.executable, str(script)], capture_output=True, text=True, timeout=600
                )
                assert out.returncode == 0, f"block {k}:\n{block}\n{out.stderr[-3000:]}"
                assert "effective_coverage" in out.stdout, out.stdout
            else:
                exec(compile(block, f"README block {k}", "exec"), namespace)
    finally:
        os.chdir(here)
    # What the blocks say they write.
    assert (work / "out" / "metrics.json").is_file()
    assert (work / "out" / "nav_path.yaml").is_file()
    assert (work / "my_plan" / "waypoints.csv").is_file()
