"""Breathing in a simulated world (``fidelity.breathing``): the sample's surface moves along its
normal with the breath, holds still (nearly) in the ventilator's breath holds, and beats with the
heart.

Measured motion: free breathing moves airways and nodules 5-18 mm superior-inferior (the carina
about 10 mm, a nodule 17.6 mm between inspiration and expiration); a ventilator's breath hold
leaves about 1 mm; the heart adds 1-2 mm near it. What the sensor feels is the part along the
surface's normal (an airway wall seen end-on, a nodule's face): ``amplitude_mm``.

Example (a scene's fidelity)::

    fidelity:
      breathing: {amplitude_mm: 3, period_s: 4, hold_s: 15, breaths: 2, residual_mm: 1}
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

from .loader import limits


@dataclass(frozen=True)
class BreathingConfig:
    """The surface's motion along its normal (positive: toward the sensor).

        ``amplitude_mm``: inspiration's displacement from end-expiration, the breath's shape Lujan's
        ``cos^(2 shape)`` (a longer dwell at expiration); ``period_s``: one breath; ``hold_s``: a
        ventilator's breath hold this long at end-expiration after every ``breaths`` breaths (0:
        free breathing, no hold); ``residual_mm``: the drift through a hold (at an even rate, taken
    back by the breaths after it);
        ``cardiac_mm`` (peak to peak) and ``cardiac_period_s``: the heart's beat, always, shaped
        as a heart's (``cardiac_shape: beat``: systole, filling, rest; ``sine``: its first harmonic
        alone), its R-R interval swinging by ``cardiac_variability`` of the period (``sim.heart``);
        ``phase``: where in its
        cycle each trial starts, drawn per trial (``random``) or at the cycle's start
        (``start``); ``gate``: the ventilator's breath-hold signal reaches the board (status bit 6
        of every frame) while a hold lasts; ``ecg``: an ECG monitor's sync pulse reaches the board
        (status bit 7) at each R wave while the heart beats (``cardiac_mm`` > 0).
    """

    amplitude_mm: float = field(default=3.0, metadata=limits(ge=-50, le=50))
    period_s: float = field(default=4.0, metadata=limits(gt=0, le=60))
    shape: int = field(default=2, metadata=limits(ge=1, le=4))
    hold_s: float = field(default=0.0, metadata=limits(ge=0, le=120))
    breaths: int = field(default=2, metadata=limits(ge=1, le=100))
    residual_mm: float = field(default=1.0, metadata=limits(ge=-10, le=10))
    cardiac_mm: float = field(default=0.0, metadata=limits(ge=0, le=10))
    cardiac_period_s: float = field(default=0.85, metadata=limits(gt=0, le=5))
    cardiac_shape: Literal["beat", "sine"] = "beat"
    cardiac_variability: float = field(default=0.04, metadata=limits(ge=0, le=0.3))
    phase: Literal["random", "start"] = "random"
    gate: bool = True
    ecg: bool = True

    @property
    def cycle(self) -> float:
        """s from one hold's start to the next's (one breath without holds)."""
        return self.breaths * self.period_s + self.hold_s if self.hold_s > 0 else self.period_s
