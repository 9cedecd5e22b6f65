"""Buckling from the tip grating's load (``estimation.detect.plateau``): the beam is a force
limiter, so the load stops rising when it buckles; a sagging beam's bending does not fool it."""

from __future__ import annotations

import numpy as np
import pytest

from palpate.estimation.detect.plateau import LoadPlateau

STEP = 2e-6  # m of advance a sample: 0.5 mm/s at 250 Hz
P_CR = 4e-3  # N, the 2.8 mm channel's beam


def record(depth_at_buckling: float, noise: float, seed: int, n: int = 900) -> tuple:
    """A Hertz load rising as delta**1.5 to P_CR at ``depth_at_buckling`` (m), then flat (the
    post-buckling elastica's rise is a few 1e-5 of P_cr over these travels), with noise."""
    u = STEP * np.arange(n)
    load = np.minimum(P_CR, P_CR * (u / depth_at_buckling) ** 1.5)
    return u, load + np.random.default_rng(seed).normal(0.0, noise, n)


def first_alarm(u: np.ndarray, load: np.ndarray) -> int | None:
    d = LoadPlateau()
    return next((i for i in range(u.size) if d.update((), float(u[i]), float(load[i]))), None)


@pytest.mark.parametrize("depth", [0.22e-3, 0.65e-3, 1.3e-3])  # 20, 3.4, 1.4 kPa at R = 1.3 mm
@pytest.mark.parametrize("noise", [0.05e-3, 0.13e-3])  # published tip gratings' resolutions
def test_the_alarm_comes_after_buckling_within_the_window(depth: float, noise: float) -> None:
    for seed in range(5):
        u, load = record(depth, noise, seed)
        i = first_alarm(u, load)
        assert i is not None
        assert depth <= u[i] <= depth + 0.12e-3  # never before; within a window (0.1 mm) after


def test_a_load_that_keeps_rising_or_stays_at_the_noise_never_alarms() -> None:
    for seed in range(5):
        u, load = record(1.9e-3, 0.05e-3, seed)  # rising to 3.7 mN, never buckling
        assert load[-1] > 0.9 * P_CR
        assert first_alarm(u, load) is None
        noise_only = np.random.default_rng(seed).normal(0.0, 0.05e-3, u.size)
        assert first_alarm(u, noise_only) is None  # flat, but at the noise: not a buckled beam


def test_without_a_load_or_after_reset_it_waits() -> None:
    d = LoadPlateau()
    assert not any(d.update((1e-4, 2e-4, 3e-4), STEP * i, None) for i in range(500))
    u, load = record(0.3e-3, 0.05e-3, 0)
    assert any(d.update((), float(a), float(p)) for a, p in zip(u, load, strict=True))
    d.reset()
    assert not d.alarm
    assert d.sigma is None
    with pytest.raises(ValueError, match="plateau_share"):
        LoadPlateau(plateau_share=1.5)
