"""k'_eps fit (paper Fig. 1d): exact line, confidence interval coverage, errors, the CLI."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pytest

from palpate.commands import calibrate
from palpate.sensor.calibration import fit_strain_coefficient, load_pairs_csv

K = 0.424e-12 / 1e-6


def test_exact_line() -> None:
    strain = np.linspace(0, 1000e-6, 11)
    fit = fit_strain_coefficient(strain, K * strain + 3e-12)
    assert fit.k_pm_per_ue == pytest.approx(0.424)
    assert fit.intercept == pytest.approx(3e-12)
    assert fit.r_squared == pytest.approx(1.0)
    lo, hi = fit.ci_pm_per_ue
    assert lo == pytest.approx(0.424)
    assert hi == pytest.approx(0.424)


def test_interval_covers_the_truth_at_its_level() -> None:
    rng = np.random.default_rng(0)
    strain = np.linspace(0, 800e-6, 20)
    covered = 0
    for _ in range(400):
        shift = K * strain + rng.normal(0, 5e-12, strain.shape)
        lo, hi = fit_strain_coefficient(strain, shift).ci
        covered += lo <= K <= hi
    assert 0.92 <= covered / 400 <= 0.98


def test_through_origin() -> None:
    strain = np.array([100e-6, 200e-6, 300e-6])
    fit = fit_strain_coefficient(strain, K * strain, through_origin=True)
    assert fit.k_pm_per_ue == pytest.approx(0.424)
    assert fit.intercept == 0.0


@pytest.mark.parametrize(
    ("strain", "shift", "match"),
    [
        ([1.0, 2.0], [1.0, 2.0], "more than 2"),
        ([1.0, 1.0, 1.0], [1.0, 2.0, 3.0], "undetermined"),
        ([1.0, 2.0, 3.0], [1.0, 2.0], "differ"),
        ([1.0, np.nan, 3.0], [1.0, 2.0, 3.0], "finite"),
    ],
)
def test_fit_errors(strain: list[float], shift: list[float], match: str) -> None:
    with pytest.raises(ValueError, match=match):
        fit_strain_coefficient(strain, shift)


def write_csv(path: Path) -> Path:
    rows = ["# glued fiber, bench calibration", "step,strain_ue,shift_pm"]
    rows += [f"{i},{s},{0.424 * s + 0.1 * (-1) ** i}" for i, s in enumerate(range(0, 1100, 100))]
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")
    return path


def test_load_pairs_csv(tmp_path: Path) -> None:
    strain, shift = load_pairs_csv(write_csv(tmp_path / "cal.csv"))
    assert strain.shape == shift.shape == (11,)
    assert strain[1] == pytest.approx(100e-6)
    bad = tmp_path / "bad.csv"
    bad.write_text("strain_ue,wavelength\n1,2\n", encoding="utf-8")
    with pytest.raises(ValueError, match="shift_pm"):
        load_pairs_csv(bad)
    bad.write_text("strain_ue,shift_pm\n1,x\n", encoding="utf-8")
    with pytest.raises(ValueError, match=r"bad\.csv: data row 2"):
        load_pairs_csv(bad)


def parse(argv: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    parser.add_argument("--json", action="store_true")
    calibrate.register(parser)
    return parser.parse_args(argv)


def test_cli_text_and_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = write_csv(tmp_path / "cal.csv")
    assert calibrate.run(parse([str(path)])) == 0
    out = capsys.readouterr().out
    assert "k'_eps" in out
    assert "R^2" in out
    assert calibrate.run(parse([str(path), "--json", "--confidence", "0.9"])) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["k_pm_per_ue"] == pytest.approx(0.424, abs=1e-3)
    assert data["confidence"] == 0.9
    assert data["ci_pm_per_ue"][0] < data["k_pm_per_ue"] < data["ci_pm_per_ue"][1]
