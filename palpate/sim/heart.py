"""The heart's beat in a simulated world (``fidelity.breathing.cardiac_*``): how far it lifts the
surface toward the sensor at a virtual time, and when an ECG monitor's R waves fall.

A heart's motion is not a sine. Each beat (``cardiac_shape: beat``) is a fast systole (the
first 30 % of the cycle, the surface out to its peak), a rapid filling (back to a fifth of it by
55 %), a slow diastasis and the atria's kick before the next beat: most of its energy in the
first harmonic, a quarter of it beyond (the estimator fits harmonics, not this shape).
``cardiac_shape: sine`` is the first harmonic alone. The rate is not steady either: the R-R
interval swings by ``cardiac_variability`` of the period (peak), over about 10 s (the Mayer
waves) and 27 s, each with a phase drawn per trial. The mechanical beat lags the R wave:
systole starts ``ECG_LAG`` of a period after it.

Usage::

    heart = Heart.of(fidelity.breathing, phase, rng)  # None: no heart
    heart.lift(2.5), heart.r_wave(2.5)         # m toward the sensor; the sync pulse is on
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..config.breathing import BreathingConfig

MM = 1e-3
ECG_PULSE = 0.02  # s: a monitor's sync output is a 10-100 ms pulse at each R wave
ECG_LAG = 0.15  # of a period: the ventricles contract 0.1-0.2 s after the R wave
SWINGS = ((10.0, 0.6), (27.0, 0.4))  # s, share of the variability: the R-R interval's swings


def beat_shape(s: float) -> float:
    """The beat's lift at ``s`` (of a cycle, 0 at systole's start), 0 to 1: systole, rapid
    filling, diastasis and the atria's kick (not zero-mean; see :data:`BEAT_MEAN`).

    >>> beat_shape(0.0), beat_shape(0.3), round(beat_shape(0.55), 2)
    (0.0, 1.0, 0.2)
    """
    s %= 1.0
    if s < 0.3:  # systole
        return 0.5 * (1.0 - math.cos(math.pi * s / 0.3))
    if s < 0.55:  # rapid filling
        return 0.2 + 0.4 * (1.0 + math.cos(math.pi * (s - 0.3) / 0.25))
    if s < 0.8:  # diastasis
        return 0.2 - 0.05 * (1.0 - math.cos(math.pi * (s - 0.55) / 0.25))
    u = (s - 0.8) / 0.2  # the atria's kick, back to rest
    return 0.1 * (1.0 - u) + 0.12 * math.sin(math.pi * u)


BEAT_MEAN = float(np.mean([beat_shape(s) for s in np.linspace(0.0, 1.0, 4000, endpoint=False)]))


@dataclass(frozen=True)
class Heart:
    """One trial's heart: the configuration, where in its cycle the trial starts (s) and the
    phases (rad) of the rate's swings."""

    config: BreathingConfig
    phase: float = 0.0
    swings: tuple[float, ...] = (0.0, 0.0)

    @classmethod
    def of(
        cls, config: BreathingConfig | None, phase: float, rng: np.random.Generator | None
    ) -> Heart | None:
        """The heart of a world (None without one), starting at ``phase`` (s); the swings' phases
        drawn from ``rng`` where the rate varies (0 without one)."""
        if config is None or not config.cardiac_mm:
            return None
        if not config.cardiac_variability or rng is None:
            return cls(config, phase)
        return cls(config, phase, tuple(float(a) for a in rng.uniform(0.0, 2 * math.pi, 2)))

    def cycles(self, t: float) -> float:
        """Beats since the world's start at ``t`` (s): the period's steady count plus its swings'
        (the rate ``1 + v cos`` of the steady one, each swing's share ``v`` of the variability)."""
        c = self.config
        tau = t + self.phase
        count = tau / c.cardiac_period_s
        for (period, share), at in zip(SWINGS, self.swings, strict=True):
            amplitude = share * c.cardiac_variability * period / (2 * math.pi * c.cardiac_period_s)
            count += amplitude * math.sin(2 * math.pi * tau / period + at)
        return count

    def lift(self, t: float) -> float:
        """The surface's displacement (m) toward the sensor at ``t`` (s), about the beat's mean;
        ``cardiac_mm`` peak to peak."""
        c, s = self.config, self.cycles(t)
        if c.cardiac_shape == "sine":
            return 0.5 * c.cardiac_mm * math.sin(2 * math.pi * s) * MM
        return c.cardiac_mm * (beat_shape(s) - BEAT_MEAN) * MM

    def r_wave(self, t: float) -> bool:
        """The ECG monitor's sync pulse is on at ``t`` (s): the first ``ECG_PULSE`` after an R
        wave, while its monitor reaches the board."""
        c = self.config
        return c.ecg and (self.cycles(t) + ECG_LAG) % 1.0 < ECG_PULSE / c.cardiac_period_s
