"""The tip force grating's sensitivity against a force scale (issue 28): from a CSV and from raw
frames that carry the scale's reading, with the reference grating's drift taken out."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from palpate.cli import main
from palpate.config import load_stack, resolve
from palpate.sensor.tipcal import fit_tip_csv, fit_tip_frames
from palpate.wire.frame import Status
from palpate.wire.frameblock import FrameBlock, encode_block

STACK = load_stack(resolve("robot-lung.yaml"))
TRUE = 7.3  # pm/mN


def test_a_force_scale_csv_gives_the_sensitivity_with_an_interval(tmp_path: Path) -> None:
    rng = np.random.default_rng(1)
    force = np.linspace(0.0, 40.0, 60)
    shift = 2.0 + TRUE * force + rng.normal(0.0, 1.0, force.size)
    path = tmp_path / "tip.csv"
    rows = "".join(f"{f:.4f},{s:.4f}\n" for f, s in zip(force, shift, strict=True))
    path.write_text("# scale vs tip grating\nforce_mn,shift_pm\n" + rows, encoding="utf-8")
    fit = fit_tip_csv(path)
    lo, hi = fit.ci_pm_per_mn
    assert lo < TRUE < hi
    assert hi - lo < 0.2
    assert fit.line.intercept == pytest.approx(2e-12, abs=1e-12)


def test_a_csv_without_the_columns_names_the_file(tmp_path: Path) -> None:
    path = tmp_path / "bad.csv"
    path.write_text("force_mn,wavelength\n1,2\n", encoding="utf-8")
    with pytest.raises(ValueError, match=r"bad\.csv"):
        fit_tip_csv(path)


def frames(n: int, drift_pm_per_frame: float, rng: np.random.Generator) -> FrameBlock:
    """The sensor pressed on a force scale: rest, then a ramp; the temperature drifts."""
    force = np.concatenate([np.zeros(40), np.linspace(0.0, 30e-3, n - 40)])  # N
    drift = drift_pm_per_frame * np.arange(n)  # pm on a grating of 10 pm/degC
    tip = STACK.sensor.tip_grating
    assert tip is not None
    tip_pm = 1560e3 + TRUE * force * 1e3 + drift * (tip.temperature_coefficient_pm_per_degc / 10)
    ref_pm = 1525e3 + drift + rng.normal(0.0, 1.0, n)
    peaks = np.tile(np.array([1530e6, 1535e6, 1540e6], dtype=np.uint32), (n, 1))
    flags = np.full(n, int(Status.FORCE_VALID), dtype=np.uint16)
    return FrameBlock(
        seq=np.arange(n, dtype=np.uint32),
        timestamp_us=np.arange(n, dtype=np.uint64) * np.uint64(1000),
        encoder=np.zeros(n, dtype=np.int32),
        flags=flags,
        peak_fm=peaks,
        reference_fm=np.round(ref_pm * 1e3).astype(np.uint32),
        force_un=np.round(force * 1e6 + rng.normal(0.0, 20.0, n)).astype(np.int32),
        tip_fm=np.round((tip_pm + rng.normal(0.0, 1.0, n)) * 1e3).astype(np.uint32),
    )


def test_raw_frames_with_the_scale_give_the_sensitivity_through_the_drift() -> None:
    stack = dataclasses.replace(STACK, board=dataclasses.replace(STACK.board, has_force=True))
    block = frames(400, 0.05, np.random.default_rng(2))  # 20 pm of drift: 2.7 mN uncompensated
    fit = fit_tip_frames(block, stack)
    lo, hi = fit.ci_pm_per_mn
    assert lo < TRUE < hi
    assert fit.sensitivity_pm_per_mn == pytest.approx(TRUE, rel=0.01)


def test_palpate_calibrate_reads_a_recorded_stream(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    robot = tmp_path / "robot.yaml"
    text = resolve("robot-lung.yaml").read_text(encoding="utf-8")
    robot.write_text(text.replace("has_force: false", "has_force: true"), encoding="utf-8")
    stream = tmp_path / "frames.bin"
    stream.write_bytes(encode_block(frames(300, 0.0, np.random.default_rng(3))))
    assert main(["calibrate", str(stream), "--tip", "--config", str(robot), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    lo, hi = out["ci_pm_per_mn"]
    assert lo < TRUE < hi
