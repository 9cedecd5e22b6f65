"""The heart's beat in a record (issue 62): R waves from the ticks with the ECG's pulse, the
phase between them, and the beat's lag and amplitude from a tip load pressed into a beating
surface (``estimation.pose.heartbeat``); and a gated trial's last attempt
(``estimation.trial.states.last_attempt``)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from palpate.estimation.pose.heartbeat import Heartbeat, heartbeat, r_waves

PERIOD, AMPLITUDE, LAG = 0.9, 0.15e-3, 0.3  # s, m (half peak to peak), of a period


def record(seconds: float, speed: float, noise: float, seed: int = 0):  # type: ignore[no-untyped-def]
    """A tip advancing at ``speed`` (m/s) into a Hertz-like surface (P = k d^1.5) that beats
    ``AMPLITUDE`` toward it, ``LAG`` of a period after each R wave; 250 rows a second."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, seconds, 0.004)
    x = speed * t
    lift = AMPLITUDE * np.sin(2 * np.pi * (t / PERIOD - LAG))
    depth = np.clip(x - 0.1e-3 + lift, 0.0, None)
    load = 3.0e3 * depth**1.5 + rng.normal(0.0, noise, t.size)
    pulses = t[(t % PERIOD) < 0.02]
    return t, x, load, pulses


def test_r_waves_are_the_first_ticks_of_each_pulse() -> None:
    t, _, _, pulses = record(5.0, 0.1e-3, 0.0)
    waves = r_waves(t.tolist(), pulses.tolist())
    assert len(waves) == 6
    assert np.allclose(np.diff(waves), PERIOD, atol=0.004)


def test_the_phase_runs_evenly_between_r_waves() -> None:
    beat = Heartbeat((1.0, 2.0, 3.2))  # past the last R wave: the median period, 1.1 s
    assert beat.phase([1.5, 2.6, 3.75]) == pytest.approx([math.pi, math.pi, math.pi])
    assert beat.period == pytest.approx(1.1)
    assert beat.lift([1.0]) == pytest.approx([0.0])


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_beat_is_measured_from_the_load(seed: int) -> None:
    t, x, load, pulses = record(6.0, 0.1e-3, 2e-5, seed)
    beat = heartbeat(x, load, t, r_waves(t.tolist(), pulses.tolist()), load > 1e-4)
    assert beat is not None
    lag = -math.atan2(beat.cos[0], beat.sin[0]) / (2 * math.pi)
    assert lag == pytest.approx(LAG, abs=0.02)
    assert beat.amplitude == pytest.approx(AMPLITUDE, rel=0.25)
    true = AMPLITUDE * np.sin(2 * np.pi * (t / PERIOD - LAG))
    fitted = beat.lift(t) * AMPLITUDE / beat.amplitude
    assert np.max(np.abs(fitted - true)) < 0.15 * AMPLITUDE


def test_a_heart_shaped_beat_is_measured_beyond_its_first_harmonic() -> None:
    """A heart's beat (sim.heart: a fast systole, a slow diastole; a quarter of its motion past
    the first harmonic) is followed within a tenth of its peak to peak, where one harmonic
    alone misses it by more than 15 % of it."""
    from palpate.sim.heart import BEAT_MEAN, beat_shape

    rng = np.random.default_rng(3)
    t = np.arange(0.0, 6.0, 0.004)
    x = 0.1e-3 * t
    true = 2 * AMPLITUDE * (np.array([beat_shape(s - LAG) for s in t / PERIOD]) - BEAT_MEAN)
    load = 3.0e3 * np.clip(x - 0.1e-3 + true, 0.0, None) ** 1.5 + rng.normal(0.0, 2e-5, t.size)
    pulses = t[(t % PERIOD) < 0.02]
    beat = heartbeat(x, load, t, r_waves(t.tolist(), pulses.tolist()), load > 1e-4)
    assert beat is not None
    assert len(beat.cos) > 1
    fitted = beat.lift(t) * AMPLITUDE / beat.amplitude
    assert np.max(np.abs(fitted - true)) < 0.2 * AMPLITUDE
    first = Heartbeat(beat.beats, beat.cos[:1], beat.sin[:1])
    alone = first.lift(t) * AMPLITUDE / first.amplitude
    assert np.max(np.abs(alone - true)) > 0.3 * AMPLITUDE


def test_no_beat_without_two_r_waves_or_enough_contact() -> None:
    t, x, load, _pulses = record(6.0, 0.1e-3, 0.0)
    assert heartbeat(x, load, t, [0.0], load > 0) is None
    assert heartbeat(x, load, t, [0.0, 0.9], np.zeros(t.size, bool)) is None


def test_a_gated_trial_is_estimated_from_its_last_attempt() -> None:
    from palpate.estimation.trial.states import last_attempt

    states = ["waiting", "approach", "indenting", "retracting", "positioning", "waiting"]
    states += ["approach", "indenting"]
    rows = [(s, float(i), ()) for i, s in enumerate(states)]
    kept, times, loads = last_attempt(rows, [float(i) for i in range(8)], [0.0] * 8)
    assert [r[0] for r in kept] == ["approach", "indenting"]
    assert times == [6.0, 7.0]
    assert loads == [0.0, 0.0]
    once = rows[:4]
    assert last_attempt(once, None, None) == (once, None, None)


def test_an_amplitude_at_the_searchs_edge_is_not_an_estimate() -> None:
    """Where the joint fit's residual still falls at the search's edge, the record has not fixed
    the beat's amplitude: the estimate fails and says so (a number there is the edge's)."""
    from palpate.estimation.jointfit.result import JointFit
    from palpate.estimation.trial.motion import HEART_SCALES, fitted_heart, unfixed

    beat = Heartbeat((0.0, 0.9, 1.8), (0.1e-3,), (0.0,))

    def falling(b: Heartbeat) -> JointFit:  # the residual falls all the way to the upper edge
        return JointFit(True, "ok", modulus=2e3, rms=1.0 / b.amplitude, n_points=100)

    def bowl(b: Heartbeat) -> JointFit:  # least at 1.2 times the first amplitude
        rms = 1.0 + (b.amplitude / 0.1e-3 - 1.2) ** 2
        return JointFit(True, "ok", modulus=2e3, rms=rms, n_points=100)

    edge = fitted_heart(beat, falling)
    assert not edge.fixed
    assert edge.amplitude == pytest.approx(HEART_SCALES[1] * 0.1e-3, rel=0.02)
    inside = fitted_heart(beat, bowl)
    assert inside.fixed
    assert inside.amplitude == pytest.approx(0.12e-3, rel=0.02)
    joint = JointFit(True, "ok", modulus=2e3, n_points=100)
    failed = unfixed(joint, edge)
    assert failed is not None
    assert not failed.success
    assert failed.modulus is None
    assert failed.message.startswith("heartbeat: the record does not fix")
    assert unfixed(joint, inside) is joint
    assert unfixed(joint, None) is joint


def test_a_beat_far_deeper_than_the_indentation_is_not_an_estimate() -> None:
    """A beat read over twice the record's deepest indentation is the fit trading the beat's
    amplitude for the modulus (fresh scenes read 10-170 mm there, 50-95 % low): no estimate;
    a beat within it stands."""
    from palpate.estimation.jointfit.result import JointFit
    from palpate.estimation.trial.motion import MAX_BEAT_OVER_DEPTH, unfixed

    beat = Heartbeat((0.0, 0.9, 1.8), (0.2e-3,), (0.0,), fixed=True)  # 0.4 mm peak to peak
    deep = JointFit(True, "ok", modulus=9e3, n_points=100, max_depth=0.6e-3)
    assert unfixed(deep, beat) is deep
    shallow = JointFit(True, "ok", modulus=3e3, n_points=100, max_depth=0.15e-3)
    assert MAX_BEAT_OVER_DEPTH * 0.15e-3 < 0.4e-3
    failed = unfixed(shallow, beat)
    assert failed is not None
    assert failed.modulus is None
    assert "the fit traded the beat's amplitude for the modulus" in failed.message
    assert failed.message.startswith("heartbeat: the beat read 0.40 mm peak to peak")


def test_r_waves_with_too_short_a_contact_for_the_beat_are_not_an_estimate() -> None:
    """An ECG on the record and no beat measured (too few rows in contact: the beam buckled
    within a beat) leaves the beat in the record: no estimate; without R waves nothing changes."""
    from palpate.estimation.jointfit.result import JointFit
    from palpate.estimation.trial.motion import unfixed

    joint = JointFit(True, "ok", modulus=4e3, n_points=100, max_depth=0.6e-3)
    failed = unfixed(joint, None, beating=True)
    assert failed is not None
    assert failed.modulus is None
    assert "contact is too short to measure the beat" in failed.message
    assert unfixed(joint, None, beating=False) is joint
    broken = JointFit(False, "no contact: too few points", n_points=100)
    assert unfixed(broken, None, beating=True) is broken  # its own reason stands
