"""The surface's motion with the breath (``fidelity.breathing``, config/breathing.py): how far
(m, along the surface's normal, positive toward the sensor) it has moved from end-expiration at
a virtual time, and whether the ventilator holds the breath then.

Each breath is Lujan's ``A sin^(2n)(pi t / T)`` (0 at end-expiration, ``A`` at inspiration);
after every ``breaths`` breaths a hold at end-expiration that drifts by ``residual_mm`` at an
even rate (``residual h / H``), an offset the next breaths take back at an even rate; the
heart's beat on top, always, and an ECG monitor's sync pulse at each of its R waves (the
mechanical beat lags the R wave: the surface starts toward the sensor ``ECG_LAG`` of a period
after it).

Usage::

    breath = Breath.of(fidelity.breathing, rng)  # None: the tissue stands still
    breath.lift(2.5), breath.holding(2.5), breath.beat(2.5)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..config.breathing import BreathingConfig

MM = 1e-3
ECG_PULSE = 0.02  # s: a monitor's sync output is a 10-100 ms pulse at each R wave
ECG_LAG = 0.15  # of a period: the ventricles contract 0.1-0.2 s after the R wave


@dataclass(frozen=True)
class Breath:
    """One trial's breathing: the configuration and where in its cycle the trial starts (s)."""

    config: BreathingConfig
    phase: float = 0.0

    @classmethod
    def of(cls, config: BreathingConfig | None, rng: np.random.Generator) -> Breath | None:
        """The breathing of a world (None without); a random phase is drawn from ``rng``."""
        if config is None:
            return None
        phase = float(rng.uniform(0.0, config.cycle)) if config.phase == "random" else 0.0
        return cls(config, phase)

    def _in_cycle(self, t: float) -> float:
        return (t + self.phase) % self.config.cycle

    def holding(self, t: float) -> bool:
        """The ventilator holds the breath at ``t`` (s)."""
        c = self.config
        return c.hold_s > 0 and self._in_cycle(t) >= c.breaths * c.period_s

    def beat(self, t: float) -> bool:
        """The ECG monitor's sync pulse is on at ``t`` (s): the first ``ECG_PULSE`` after an R
        wave, while the heart beats and its monitor reaches the board."""
        c = self.config
        if not (c.ecg and c.cardiac_mm):
            return False
        return (t + self.phase + ECG_LAG * c.cardiac_period_s) % c.cardiac_period_s < ECG_PULSE

    def lift(self, t: float) -> float:
        """The surface's displacement (m) toward the sensor at ``t`` (s)."""
        c = self.config
        tau = self._in_cycle(t)
        breathing = c.breaths * c.period_s if c.hold_s > 0 else c.period_s
        if tau < breathing:
            lift = c.amplitude_mm * math.sin(math.pi * (tau % c.period_s) / c.period_s) ** (
                2 * c.shape
            )
            if c.hold_s > 0:  # the last hold's drift, taken back
                lift += c.residual_mm * (1.0 - tau / breathing)
        else:
            lift = c.residual_mm * (tau - breathing) / c.hold_s
        if c.cardiac_mm:
            lift += (
                0.5 * c.cardiac_mm * math.sin(2 * math.pi * (t + self.phase) / c.cardiac_period_s)
            )
        return lift * MM
