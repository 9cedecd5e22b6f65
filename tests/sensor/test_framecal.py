"""k'_eps from a raw frame stream of the sensor buckling on a rigid reference (synthetic)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from palpate.config.schema import MM, StackConfig
from palpate.estimation.beam.model import Beam
from palpate.estimation.beam.section import grating_intervals, sensor_section
from palpate.sensor.framecal import calibrate_frames, read_frames
from palpate.wire.dynamixel import TICKS_PER_REV
from palpate.wire.frameblock import FrameBlock, encode_block

STACK = StackConfig()
L = 44e-3


def stream(
    k_pm_per_ue: float, x0: float, rng: np.random.Generator, noise_pm: float, end: float = 1.5e-3
) -> bytes:
    """Frames of the stage advancing to ``end`` past a rigid reference's contact at x0, the
    peaks shifted by k times the elastica's grating strains at e = u - x0, plus noise."""
    s = STACK.sensor
    beam = Beam.from_section(sensor_section(s), L)
    step = STACK.drive.lead / TICKS_PER_REV
    counts = np.round(np.linspace(x0 - 2.5e-3, x0 + end, 1500) / step).astype(np.int32)
    counts = np.concatenate([np.full(40, counts[0]), counts])  # at rest first
    e = np.clip(counts * step - x0, 0.0, None)
    strain = beam.grating_strains(e, grating_intervals(s, L), include_axial=True)
    base = np.array([STACK.fbg.base_wavelengths_nm[g - 1] for g in s.used_gratings]) * 1e-9
    k = k_pm_per_ue * 1e-12 / 1e-6
    wl = base + k * strain + rng.normal(0.0, noise_pm * 1e-12, strain.shape)
    n = counts.size
    block = FrameBlock(
        seq=np.arange(n, dtype=np.uint32),
        timestamp_us=(np.arange(n) * 4000).astype(np.uint64),
        encoder=counts,
        flags=np.zeros(n, dtype=np.uint16),
        peak_fm=np.round(wl / 1e-15).astype(np.uint32),
    )
    return b"\x00garbage" + encode_block(block)


def test_the_strain_coefficient_comes_back_from_a_recorded_stream(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    path = tmp_path / "frames.bin"
    path.write_bytes(stream(0.424, 30e-3, rng, noise_pm=1.0))
    block = read_frames(path, STACK)
    fit = calibrate_frames(block, STACK, L, rest_frames=20)
    assert fit.through_origin
    assert fit.k_pm_per_ue == pytest.approx(0.424, rel=0.01)
    lo, hi = fit.ci_pm_per_ue
    assert lo < fit.k_pm_per_ue < hi


def test_a_stream_without_buckling_or_frames_is_refused(tmp_path: Path) -> None:
    empty = tmp_path / "empty.bin"
    empty.write_bytes(b"no frames here" * 10)
    with pytest.raises(ValueError, match="no valid frame"):
        read_frames(empty, STACK)
    rng = np.random.default_rng(1)
    path = tmp_path / "free.bin"
    path.write_bytes(stream(0.424, 30e-3, rng, noise_pm=1.0, end=-0.5e-3))  # never touches
    with pytest.raises(ValueError, match="never reaches buckling"):
        calibrate_frames(read_frames(path, STACK), STACK, 42 * MM)
