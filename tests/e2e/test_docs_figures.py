"""The figures in docs/img show today's numbers: ``bench/docs_figures.py --check`` reruns the
seeded campaign and survey behind each (the README's estimates, docs/maps.md's map) and compares
their data with the JSON shipped beside the figure (relative 1e-3, verdicts exactly). A change
that moves them fails here until ``python bench/docs_figures.py`` rebuilds the figures."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.slow
def test_the_docs_figures_data_are_today_s() -> None:
    run = subprocess.run(
        [sys.executable, str(ROOT / "bench" / "docs_figures.py"), "--check"],
        capture_output=True,
        text=True,
        timeout=900,
        check=False,
    )
    assert run.returncode == 0, run.stdout + run.stderr
    assert "estimates: data" in run.stdout
    assert "map-active: data" in run.stdout
