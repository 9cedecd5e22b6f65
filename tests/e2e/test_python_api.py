"""docs/python-api.md's code blocks, the README's and examples/'s scripts run as a user runs
them: in a fresh interpreter, from a folder holding decoy config.py, sim.py and robot.py (the
stack installs under palpate: docs/architecture.md); the README's from the checkout's root, as
its paths are written."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "python-api.md"
EXAMPLES = sorted((ROOT / "examples").glob("*.py"))
BLOCK = re.compile(r"```python\n(.*?)```", re.S)


def decoys(folder: Path) -> Path:
    for name in ("config", "sim", "robot"):
        (folder / f"{name}.py").write_text("raise ImportError('a decoy was imported')\n")
    return folder


def run(folder: Path, *argv: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, *argv], cwd=folder, capture_output=True, text=True, check=False
    )


@pytest.mark.slow
def test_every_block_of_the_python_api_page_runs(tmp_path: Path) -> None:
    blocks = BLOCK.findall(DOC.read_text(encoding="utf-8"))
    assert len(blocks) >= 5
    script = decoys(tmp_path) / "doc_blocks.py"
    script.write_text("\n".join(blocks), encoding="utf-8")  # in order: later blocks use earlier
    out = run(tmp_path, script.name)
    assert out.returncode == 0, out.stderr
    assert "<python>" in out.stdout
    assert "samples[0].modulus_kpa" in out.stdout
    assert "results.json" in out.stdout


@pytest.mark.slow
def test_the_readme_s_python_runs_from_the_checkout(tmp_path: Path) -> None:
    [block] = BLOCK.findall((ROOT / "README.md").read_text(encoding="utf-8"))
    script = tmp_path / "readme_block.py"
    script.write_text(block, encoding="utf-8")
    out = run(ROOT, str(script))
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    assert len(lines) == 3
    assert all(" kPa " in line for line in lines)


def test_there_are_examples() -> None:
    assert len(EXAMPLES) >= 3


@pytest.mark.slow
@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.name)
def test_each_example_runs(script: Path, tmp_path: Path) -> None:
    out = run(decoys(tmp_path), str(script))
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip()
