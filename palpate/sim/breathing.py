"""The surface's motion with the breath (``fidelity.breathing``, config/breathing.py): how far
(m, along the surface's normal, positive toward the sensor) it has moved from end-expiration at
a virtual time, and whether the ventilator holds the breath then.

Each breath is Lujan's ``A sin^(2n)(pi t / T)`` (0 at end-expiration, ``A`` at inspiration);
after every ``breaths`` breaths a hold at end-expiration that drifts by ``residual_mm`` at an
even rate (``residual h / H``), an offset the next breaths take back at an even rate; the
heart's beat on top, always, and an ECG monitor's sync pulse at each of its R waves
(``sim.heart``).

Usage::

    breath = Breath.of(fidelity.breathing, rng)  # None: the tissue stands still
    breath.lift(2.5), breath.holding(2.5), breath.beat(2.5)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..config.breathing import BreathingConfig
from .heart import Heart

MM = 1e-3


@dataclass(frozen=True)
class Breath:
    """One trial's breathing: the configuration and where in its cycle the trial starts (s)."""

    config: BreathingConfig
    phase: float = 0.0
    heart: Heart | None = None  # where not given: the config's at ``phase``, swings' phases 0

    def __post_init__(self) -> None:
        if self.heart is None:
            object.__setattr__(self, "heart", Heart.of(self.config, self.phase, None))

    @classmethod
    def of(cls, config: BreathingConfig | None, rng: np.random.Generator) -> Breath | None:
        """The breathing of a world (None without); a random phase is drawn from ``rng``."""
        if config is None:
            return None
        phase = float(rng.uniform(0.0, config.cycle)) if config.phase == "random" else 0.0
        return cls(config, phase, Heart.of(config, phase, rng))

    def _in_cycle(self, t: float) -> float:
        return (t + self.phase) % self.config.cycle

    def holding(self, t: float) -> bool:
        """The ventilator holds the breath at ``t`` (s)."""
        c = self.config
        return c.hold_s > 0 and self._in_cycle(t) >= c.breaths * c.period_s

    def beat(self, t: float) -> bool:
        """The ECG monitor's sync pulse is on at ``t`` (s): the first ``ECG_PULSE`` after an R
        wave, while the heart beats and its monitor reaches the board."""
        return self.heart is not None and self.heart.r_wave(t)

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
        return lift * MM + (0.0 if self.heart is None else self.heart.lift(t))
