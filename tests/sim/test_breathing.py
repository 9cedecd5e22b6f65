"""Breathing in the world (issue 42): the surface's displacement along its normal with each
breath, the ventilator's holds and their residual drift, the heart; the gate bit in the board's
frames while a hold lasts."""

from __future__ import annotations

import numpy as np
import pytest

from palpate.config.breathing import BreathingConfig
from palpate.sim.breathing import Breath
from palpate.wire.frame import Status

HELD = BreathingConfig(
    amplitude_mm=2.0, period_s=4.0, hold_s=15.0, breaths=2, residual_mm=1.0, phase="start"
)


def test_a_breath_rises_to_its_amplitude_and_rests_at_expiration() -> None:
    breath = Breath(HELD)
    assert breath.lift(0.0) == pytest.approx(1e-3)  # the last hold's drift, being taken back
    assert breath.lift(2.0) == pytest.approx(2e-3 + 0.75e-3)  # inspiration, 2 s into 8
    assert not breath.holding(7.9)
    assert breath.holding(8.0)
    assert breath.lift(8.0) == pytest.approx(0.0, abs=1e-12)  # the hold starts at expiration
    assert breath.lift(15.5) == pytest.approx(0.5e-3)  # drifting at an even rate
    assert breath.holding(22.9)
    assert not breath.holding(23.0)


def test_the_motion_is_continuous() -> None:
    breath = Breath(HELD)
    t = np.arange(0.0, 3 * HELD.cycle, 1e-3)
    lift = np.array([breath.lift(x) for x in t])
    assert np.max(np.abs(np.diff(lift))) < 1e-5  # 10 um a millisecond at most


def test_the_heart_beats_on_top_and_free_breathing_never_holds() -> None:
    sine = {"cardiac_shape": "sine", "cardiac_variability": 0.0}
    free = Breath(
        BreathingConfig(hold_s=0.0, cardiac_mm=1.0, cardiac_period_s=1.0, phase="start", **sine)  # type: ignore[arg-type]
    )
    assert free.config.cycle == 4.0
    assert not any(free.holding(x) for x in np.arange(0.0, 20.0, 0.1))
    assert free.lift(0.25) == pytest.approx(3e-3 * np.sin(np.pi / 16) ** 4 + 0.5e-3)


def test_each_trial_starts_somewhere_in_the_cycle() -> None:
    rng = np.random.default_rng(0)
    phases = {Breath.of(HELD.__class__(hold_s=15.0), rng).phase for _ in range(5)}  # type: ignore[union-attr]
    assert len(phases) == 5
    assert Breath.of(None, rng) is None
    assert Status.BREATH_HOLD == 1 << 6


def test_the_ecg_pulses_once_a_beat_ahead_of_the_motion() -> None:
    """A 20 ms sync pulse at each R wave, only while the heart beats and its monitor is on; the
    surface starts toward the sensor ECG_LAG of a period after it (a sine's beat, the rate
    steady)."""
    from palpate.sim.heart import ECG_LAG, ECG_PULSE

    steady = {"cardiac_shape": "sine", "cardiac_variability": 0.0}
    beating = Breath(BreathingConfig(cardiac_mm=0.4, cardiac_period_s=0.8, phase="start", **steady))  # type: ignore[arg-type]
    t = np.arange(0.0, 8.0, 0.004)
    on = np.array([beating.beat(x) for x in t])
    rises = t[1:][on[1:] & ~on[:-1]]
    assert len(rises) == 10
    assert np.allclose(np.diff(rises), 0.8, atol=0.005)
    assert np.count_nonzero(on) == pytest.approx(10 * ECG_PULSE / 0.004, abs=10)
    heart = np.array([beating.lift(x) for x in t]) - np.array(
        [Breath(BreathingConfig(phase="start")).lift(x) for x in t]
    )
    start = rises[0] + ECG_LAG * 0.8  # the heart's lift crosses its mean upward here
    assert heart[np.searchsorted(t, start)] == pytest.approx(0.0, abs=2e-6)
    assert heart[np.searchsorted(t, start + 0.2)] == pytest.approx(0.2e-3, rel=0.01)
    quiet = Breath(BreathingConfig(cardiac_mm=0.0, phase="start"))
    unmonitored = Breath(BreathingConfig(cardiac_mm=0.4, ecg=False, phase="start"))
    assert not any(quiet.beat(x) or unmonitored.beat(x) for x in t)
    assert Status.CARDIAC_TRIGGER == 1 << 7
