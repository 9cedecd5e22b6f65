"""What ships and what does not: the wheel holds the product (``palpate``, its data) and no
benchmark or fuzz harness; ``palpate bench`` finds the checkout's ``benchmarks/`` and names the
same sections."""

from __future__ import annotations

import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

import benchmarks
from palpate.commands.bench import SECTION_NAMES

ROOT = Path(__file__).resolve().parent.parent


def test_palpate_bench_names_the_sections_the_checkout_has() -> None:
    assert list(SECTION_NAMES) == list(benchmarks.SECTIONS)


@pytest.mark.slow
def test_the_wheel_holds_the_product_and_no_benchmark(tmp_path: Path) -> None:
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "-q",
         "-w", str(tmp_path), str(ROOT)],
        check=True, capture_output=True,
    )  # fmt: skip
    [wheel] = tmp_path.glob("palpate-*.whl")
    names = zipfile.ZipFile(wheel).namelist()
    tops = {n.split("/")[0] for n in names if not n.split("/")[0].endswith(".dist-info")}
    assert tops == {"palpate"}
    assert not [n for n in names if "benchmark" in n or "fuzz" in n]
    for data in (
        "palpate/config/robot.yaml",
        "palpate/estimation/contact/finite_strain/departure.npz",
    ):
        assert data in names
    assert any(n.startswith("palpate/sim/fem/tables/") for n in names)
    assert "palpate/robot/trial/session.py" in names
