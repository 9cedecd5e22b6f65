"""The x-y stage under the sample (``stage:`` of the robot file; issue 40): two more Dynamixel
axes on the drive's bus, each a lead screw, that put the sensor's tip over any point of a patch
for a stiffness map. Re-exported by :mod:`config.schema`; optional (a robot without it has
``stack.stage is None``)::

    stage:
      x: {id: 4, model: XL430-W250}
      y: {id: 5, model: XL430-W250}
      lead_mm_per_rev: 2
      x_travel_mm: [-15, 15]
      y_travel_mm: [-15, 15]

A stage position ``(x, y)`` names the point of the sample under the tip, in the frame of the
sample's single-trial point (where the tip presses at the stage's home, ``(0, 0)`` unless
``home_mm`` says otherwise): moving the stage to ``(x, y)`` slides the sample by ``-(x, y)``.

``carries: robot`` (issue 58) is a gantry that carries the robot instead, as a lab's gantry on
the bench or a guide sheath in the body does, the tissue staying where it is: the stage at
``(x, y)`` moves the robot's base frame by ``x * x_direction + y * y_direction`` (unit vectors
of the base frame, orthogonal). Set them in the tissue's plane (the defaults: across the
straight tube's axis) and a position names the point of the tissue the tip presses, as for the
sample.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

from .loader import limits
from .optics import MM
from .servo import ServoConfig


@dataclass(frozen=True)
class XYStageConfig:
    """Two lead-screw axes (m of travel per servo revolution: ``lead_mm_per_rev``), their
    travel (the guards: a goal outside is refused before anything moves), speed and
    acceleration, the home pose the stage is in at power-up (software homing, as the drive's),
    and how close to a goal counts as arrived."""

    x: ServoConfig = ServoConfig(id=4, model="XL430-W250")  # noqa: RUF009 - frozen
    y: ServoConfig = ServoConfig(id=5, model="XL430-W250")  # noqa: RUF009 - frozen
    lead_mm_per_rev: float = field(default=2.0, metadata=limits(gt=0, le=100))
    x_travel_mm: tuple[float, float] = (-15.0, 15.0)
    y_travel_mm: tuple[float, float] = (-15.0, 15.0)
    home_mm: tuple[float, float] = (0.0, 0.0)
    max_speed_mm_per_s: float = field(default=5.0, metadata=limits(gt=0, le=500))
    max_accel_mm_per_s2: float = field(default=50.0, metadata=limits(gt=0, le=10000))
    arrived_mm: float = field(default=0.02, metadata=limits(gt=0, le=5))
    carries: Literal["sample", "robot"] = "sample"
    x_direction: tuple[float, float, float] = (0.0, 1.0, 0.0)  # carries: robot
    y_direction: tuple[float, float, float] = (0.0, 0.0, -1.0)

    def validate(self) -> None:
        if self.x.id == self.y.id:
            raise ValueError(f"x.id and y.id must differ, got {self.x.id}")
        dx, dy = self.x_direction, self.y_direction
        for key, d in (("x_direction", dx), ("y_direction", dy)):
            if not abs(math.hypot(*d) - 1.0) <= 1e-6:
                raise ValueError(f"{key}: a unit vector of the base frame, got {list(d)}")
        if not abs(sum(a * b for a, b in zip(dx, dy, strict=True))) <= 1e-6:
            raise ValueError(f"y_direction: orthogonal to x_direction, got {list(dy)}")
        for axis, (lo, hi), home in (
            ("x", self.x_travel_mm, self.home_mm[0]),
            ("y", self.y_travel_mm, self.home_mm[1]),
        ):
            if not lo < hi:
                raise ValueError(f"{axis}_travel_mm: [{lo}, {hi}] is not [min, max]")
            if not lo <= home <= hi:
                raise ValueError(f"home_mm: {axis} = {home} is outside {axis}_travel_mm")

    @property
    def lead(self) -> float:
        """Travel per servo revolution (m)."""
        return self.lead_mm_per_rev * MM

    @property
    def travel(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """(x_min, x_max), (y_min, y_max) in m."""
        return (
            (self.x_travel_mm[0] * MM, self.x_travel_mm[1] * MM),
            (self.y_travel_mm[0] * MM, self.y_travel_mm[1] * MM),
        )

    @property
    def home(self) -> tuple[float, float]:
        return self.home_mm[0] * MM, self.home_mm[1] * MM

    @property
    def max_speed(self) -> float:
        return self.max_speed_mm_per_s * MM

    @property
    def max_accel(self) -> float:
        return self.max_accel_mm_per_s2 * MM

    @property
    def arrived(self) -> float:
        return self.arrived_mm * MM
