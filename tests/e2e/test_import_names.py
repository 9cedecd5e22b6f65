"""A user's folder holding its own config.py, sim.py, robot.py, sensor.py, wire.py and
estimation.py does not break palpate, from Python or from the command line: the stack's
layers are installed and imported as palpate.config, palpate.sim, ... (docs/architecture.md)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

DECOYS = ("config", "sim", "robot", "sensor", "wire", "estimation")

SCRIPT = """
import config, sim  # the user's own modules, found first beside the script
assert config.MINE and sim.MINE
from palpate.config import load_stack
from palpate.sim.clock import VirtualClock
stack = load_stack()
print(stack.sensor.tip_radius, VirtualClock().now, config.MINE)
"""


def decoy_folder(tmp_path: Path) -> Path:
    for name in DECOYS:
        (tmp_path / f"{name}.py").write_text("MINE = True\n", encoding="utf-8")
    return tmp_path


def test_a_script_beside_decoys_imports_palpate_and_its_own_modules(tmp_path: Path) -> None:
    folder = decoy_folder(tmp_path)
    (folder / "script.py").write_text(SCRIPT, encoding="utf-8")
    out = subprocess.run(
        [sys.executable, "script.py"], cwd=folder, capture_output=True, text=True, check=False
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.split()[-1] == "True"


@pytest.mark.slow
def test_the_command_line_beside_decoys_runs_a_campaign(tmp_path: Path) -> None:
    folder = decoy_folder(tmp_path)
    argv = ["-m", "palpate.cli", "sim", "--campaign", "bench", "--limit", "1", "--workers", "1",
            "--no-plots", "--out", "out"]  # fmt: skip
    out = subprocess.run(
        [sys.executable, *argv], cwd=folder, capture_output=True, text=True, check=False
    )
    assert out.returncode == 0, out.stderr
    assert "1 trials" in out.stdout
