"""The dual roller-gear drive's configuration (``drive:`` of the robot file); re-exported by
:mod:`config.schema`."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from .loader import limits
from .optics import MM


@dataclass(frozen=True)
class DriveConfig:
    """Dual roller-gear drive: joint space (roll phi, stage translation) <-> servo shaft angles.

    Servo shaft angles: outer = outer_roll_ratio * phi, inner = inner_roll_ratio * phi (the inner
    roll is slaved to the outer one so the sensor does not twist), translation servo =
    2 pi / lead * (translation - coupling * phi). ``coupling_mm_per_rad`` is the translation a
    roll produces by itself (0 for an ideal roller gear). ``home_*`` is the pose the drive is in
    when it is homed (software homing: present shaft angles are taken as this pose).
    """

    outer_roll_ratio: float = field(default=1.0, metadata=limits(gt=0, le=1000))
    inner_roll_ratio: float = field(default=1.0, metadata=limits(gt=0, le=1000))
    lead_mm_per_rev: float = field(default=20.0, metadata=limits(gt=0, le=1000))
    coupling_mm_per_rad: float = field(default=0.0, metadata=limits(ge=-100, le=100))
    translation_min_mm: float = field(default=0.0, metadata=limits(ge=-1000, le=1000))
    translation_max_mm: float = field(default=80.0, metadata=limits(ge=-1000, le=1000))
    roll_min_deg: float = field(default=-200.0, metadata=limits(ge=-3600, le=3600))
    roll_max_deg: float = field(default=200.0, metadata=limits(ge=-3600, le=3600))
    max_speed_mm_per_s: float = field(default=5.0, metadata=limits(gt=0, le=1000))
    max_roll_speed_deg_per_s: float = field(default=90.0, metadata=limits(gt=0, le=10000))
    max_accel_mm_per_s2: float = field(default=50.0, metadata=limits(gt=0, le=100000))
    max_roll_accel_deg_per_s2: float = field(default=360.0, metadata=limits(gt=0, le=1000000))
    home_translation_mm: float = field(default=0.0, metadata=limits(ge=-1000, le=1000))
    home_roll_deg: float = field(default=0.0, metadata=limits(ge=-3600, le=3600))
    # The inner roller gear is slaved to the outer one; a twist between them beyond this (a
    # slipping gear, a stalled servo) stops the trial and retracts.
    max_twist_deg: float = field(default=3.0, metadata=limits(gt=0, le=360))

    def validate(self) -> None:
        if self.translation_min_mm >= self.translation_max_mm:
            raise ValueError("translation_min_mm must be below translation_max_mm")
        if self.roll_min_deg >= self.roll_max_deg:
            raise ValueError("roll_min_deg must be below roll_max_deg")
        if not self.translation_min_mm <= self.home_translation_mm <= self.translation_max_mm:
            raise ValueError("home_translation_mm must lie within the translation limits")
        if not self.roll_min_deg <= self.home_roll_deg <= self.roll_max_deg:
            raise ValueError("home_roll_deg must lie within the roll limits")

    @property
    def lead(self) -> float:
        """Translation of the inner roller gear per servo revolution, in m."""
        return self.lead_mm_per_rev * MM

    @property
    def coupling(self) -> float:
        """Translation per rad of roll, m/rad."""
        return self.coupling_mm_per_rad * MM

    @property
    def translation_limits(self) -> tuple[float, float]:
        return self.translation_min_mm * MM, self.translation_max_mm * MM

    @property
    def roll_limits(self) -> tuple[float, float]:
        return math.radians(self.roll_min_deg), math.radians(self.roll_max_deg)

    @property
    def max_speed(self) -> float:
        return self.max_speed_mm_per_s * MM

    @property
    def max_twist(self) -> float:
        return math.radians(self.max_twist_deg)

    @property
    def max_roll_speed(self) -> float:
        return math.radians(self.max_roll_speed_deg_per_s)

    @property
    def max_accel(self) -> float:
        return self.max_accel_mm_per_s2 * MM

    @property
    def max_roll_accel(self) -> float:
        return math.radians(self.max_roll_accel_deg_per_s2)

    @property
    def home_translation(self) -> float:
        return self.home_translation_mm * MM

    @property
    def home_roll(self) -> float:
        return math.radians(self.home_roll_deg)
