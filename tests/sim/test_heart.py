"""The heart in the world (issue 62): a heart's beat, not a sine (a fast systole, a slow
diastole and rest: a quarter of its motion beyond the first harmonic), at a rate that swings
from beat to beat, its R waves the ECG's; each trial's swings drawn apart."""

from __future__ import annotations

import numpy as np
import pytest

from palpate.config.breathing import BreathingConfig
from palpate.sim.heart import BEAT_MEAN, ECG_LAG, Heart, beat_shape

BEATING = BreathingConfig(cardiac_mm=0.4, cardiac_period_s=0.8, cardiac_variability=0.1)


def test_a_beat_rises_fast_and_falls_slowly_to_rest() -> None:
    s = np.linspace(0.0, 1.0, 2000, endpoint=False)
    w = np.array([beat_shape(x) for x in s])
    assert w.min() == pytest.approx(0.0)
    assert w.max() == pytest.approx(1.0)
    assert s[np.argmax(w)] == pytest.approx(0.3, abs=0.001)  # systole: a third of the cycle
    assert np.max(np.abs(np.diff(w))) < 0.01  # continuous
    assert abs(BEAT_MEAN - np.mean(w)) < 1e-3
    power = np.abs(np.fft.rfft(w - w.mean())[1:10]) ** 2
    assert 0.15 < power[1:].sum() / power.sum() < 0.35  # past the first harmonic


def test_the_lift_is_cardiac_mm_peak_to_peak_about_its_mean() -> None:
    heart = Heart(BreathingConfig(cardiac_mm=0.4, cardiac_period_s=0.8, cardiac_variability=0.0))
    t = np.arange(0.0, 8.0, 0.002)
    lift = np.array([heart.lift(x) for x in t])
    assert np.ptp(lift) == pytest.approx(0.4e-3, rel=0.01)
    assert np.mean(lift) == pytest.approx(0.0, abs=5e-6)


def test_the_rate_swings_and_each_r_wave_leads_its_systole() -> None:
    heart = Heart.of(BEATING, 0.0, np.random.default_rng(1))
    assert heart is not None
    assert heart.swings != (0.0, 0.0)
    t = np.arange(0.0, 60.0, 0.004)
    on = np.array([heart.r_wave(x) for x in t])
    rises = t[1:][on[1:] & ~on[:-1]]
    intervals = np.diff(rises)
    assert intervals.mean() == pytest.approx(0.8, rel=0.02)
    assert 0.03 < np.ptp(intervals) / 0.8 < 0.25  # the R-R interval swings by the variability
    lift = np.array([heart.lift(x) for x in t])
    for r in rises[1:-1]:  # systole starts ECG_LAG of a beat after its R wave: the trough
        quiet = lift[np.searchsorted(t, r + ECG_LAG * 0.8)]
        assert quiet == pytest.approx(lift.min(), abs=0.03e-3)
    other = Heart.of(BEATING, 0.0, np.random.default_rng(2))
    assert other is not None
    assert other.swings != heart.swings


def test_no_heart_no_heart() -> None:
    assert Heart.of(BreathingConfig(cardiac_mm=0.0), 0.0, np.random.default_rng(0)) is None
    assert Heart.of(None, 0.0, None) is None
