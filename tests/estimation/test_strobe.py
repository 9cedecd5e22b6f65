"""The record read in the heart's quiet phase (issue 62, ``estimation.trial.strobe``): the quiet
phase from the R waves, the rows outside it set aside, the windows a read needs, and the drift's
velocity where the fit's residual is least, with its standard error from the curvature."""

from __future__ import annotations

import math

import numpy as np
import pytest

from palpate.estimation.jointfit import JointFit
from palpate.estimation.pose.heartbeat import QUIET, in_quiet_phase, r_waves
from palpate.estimation.trial.motion import least_residual
from palpate.estimation.trial.strobe import OFF_BEAT, held_rows, strobe_fit, strobed_rows

RATE = 250.0  # rows a second
PERIOD = 0.85


def test_the_quiet_phase_follows_each_r_r_interval() -> None:
    beats = [0.0, 0.8, 1.8]  # a long interval after a short one
    quiet = in_quiet_phase([0.6, 0.74, 1.6, 1.5, 2.5], beats).tolist()
    # 0.75, 0.925, 0.8 and 0.7 of their intervals; past the last R wave at the median, 0.78
    assert quiet == [True, False, True, False, True]
    assert not in_quiet_phase([-0.2], beats)[0]  # before the first R wave: no phase


def record(held_s: float, noise: float = 1e-5, seed: int = 0):  # type: ignore[no-untyped-def]
    """Rows of a trial beside a heart: the approach for 2 s, indenting 2-6 s (a load rising as
    (t - 2)^1.5), then buckled at one advance for ``held_s``; R-wave pulses of 20 ms."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 6.0 + held_s, 1.0 / RATE)
    state = np.where(t < 2.0, "approach", np.where(t < 6.0, "indenting", "buckled"))
    advance = 1e-4 * np.minimum(t, 6.0)
    load = 2e-3 * np.clip(np.minimum(t, 6.0) - 2.0, 0.0, None) ** 1.5
    load = load + rng.normal(0.0, noise, t.size)
    rows = [(str(s), float(u), ()) for s, u in zip(state, advance, strict=True)]
    pulses = [float(x) for x in t if x % PERIOD < 0.02]
    return rows, t.tolist(), load.tolist(), pulses


def test_the_rows_outside_the_quiet_phase_are_set_aside() -> None:
    rows, times, loads, pulses = record(held_s=2.5)
    strobe = strobed_rows(rows, times, loads, pulses)
    assert strobe is not None
    quiet = in_quiet_phase(times, r_waves(times, pulses))
    for (kept, _, _), (state, _, _), q in zip(strobe.rows, rows, quiet, strict=True):
        assert kept == (state if q else OFF_BEAT)
    phase = (strobe.touch % PERIOD) / PERIOD
    assert 2.0 < strobe.touch < 6.0
    assert QUIET[0] <= phase <= QUIET[1]
    assert 6.0 + PERIOD < strobe.release <= times[-1]
    assert held_rows(rows).sum() == sum(1 for r in rows if r[0] == "buckled")


def test_too_few_quiet_windows_held_after_buckling_read_nothing() -> None:
    rows, times, loads, pulses = record(held_s=0.5)  # less than one quiet window held
    assert strobed_rows(rows, times, loads, pulses) is None
    rows, times, loads, pulses = record(held_s=2.5)
    assert strobed_rows(rows, times, loads, None) is None  # no ECG
    assert strobed_rows(rows, times, None, pulses) is None  # no tip grating


def parabola(vertex: float, width: float, n: int = 100):  # type: ignore[no-untyped-def]
    """A fit whose rms^2 is 1 + ((x - vertex) / width)^2 over ``n`` points."""

    def fit(x: float) -> JointFit:
        rms = math.sqrt(1.0 + ((x - vertex) / width) ** 2)
        return JointFit(True, "ok", modulus=1e3 + x, rms=rms, n_points=n, noise_scale=1.0)

    return fit


def test_the_least_residual_and_its_error_from_the_curvature() -> None:
    least = least_residual(parabola(0.3e-3, 0.1e-3), (-1e-3, 1e-3), 1e-8, 0.01e-3, 0.02e-3)
    assert least.found
    assert not least.edge
    assert least.best == pytest.approx(0.3e-3, abs=0.001e-3)
    # chi^2 = n rms^2 rises 1 at one standard error
    assert least.sigma == pytest.approx(0.1e-3 / math.sqrt(100), rel=0.05)
    assert least.joint is not None
    assert least.joint.modulus == pytest.approx(1e3 + least.best)


def test_a_least_at_the_searchs_edge_is_not_a_value() -> None:
    edge = least_residual(parabola(2e-3, 0.1e-3), (-1e-3, 1e-3), 1e-8, 0.01e-3, 0.02e-3)
    assert edge.found
    assert edge.edge
    assert math.isnan(edge.sigma)
    assert edge.joint is None
    failed = least_residual(lambda x: None, (-1e-3, 1e-3), 1e-8, 0.01e-3, 0.02e-3)
    assert not failed.found
    assert failed.joint is None


def test_the_drift_where_the_residual_is_least_and_its_interval() -> None:
    """A fit that reads the rows' drift (the quiet rows' advance against the recorded one) and
    is best at 0.05 mm/s toward the sensor: the motion spans the strobe, the interval the fits
    3 standard errors either side."""
    rows, times, loads, pulses = record(held_s=2.5)
    strobe = strobed_rows(rows, times, loads, pulses)
    assert strobe is not None
    t1, u1 = times[-1], rows[-1][1]

    def fit(taken: list[tuple[str, float, tuple[float, ...]]]) -> JointFit:
        assert all(r[0] == k[0] for r, k in zip(taken, strobe.rows, strict=True))
        velocity = (taken[-1][1] - u1) / (t1 - strobe.touch)
        rms = math.sqrt(1.0 + ((velocity - 0.05e-3) / 0.01e-3) ** 2)
        modulus = 1e4 * (1 + velocity * 1e3)
        return JointFit(
            True, "ok", modulus=modulus, ci_low=modulus - 500, ci_high=modulus + 500,
            rms=rms, n_points=400, noise_scale=1.0,
        )  # fmt: skip

    joint, motion = strobe_fit(strobe, times, True, fit)
    assert motion is not None
    assert motion.velocity == pytest.approx(0.05e-3, abs=0.002e-3)
    assert motion.touch == strobe.touch
    assert motion.release == strobe.release
    assert joint is not None
    assert joint.success
    assert joint.ci_low is not None
    assert joint.ci_high is not None
    spread = 3 * motion.velocity_sigma * 1e3 * 1e4  # the modulus at 3 sigma of the drift
    assert spread > 0
    assert joint.ci_high == pytest.approx(joint.modulus + spread + 500, rel=0.01)
    assert joint.ci_low == pytest.approx(joint.modulus - spread - 500, rel=0.01)
    plain, none = strobe_fit(strobe, times, False, fit)  # no drift expected: none fitted
    assert none is None
    assert plain is not None
