"""Which servos a bus carries, by the names the drive and the stage use: the roller-gear drive's
three, and the x-y stage's two when the robot has one (``stage:`` of the robot file)."""

from __future__ import annotations

from dataclasses import dataclass

from ...config.schema import ServoBusConfig, XYStageConfig, servo_roster


@dataclass(frozen=True)
class Motor:
    """A servo on the bus: the name the drive uses, its bus ID and its model."""

    name: str
    id: int
    model: str


def bus_motors(cfg: ServoBusConfig, stage: XYStageConfig | None = None) -> list[Motor]:
    """The drive's servos of ``cfg``, then the stage's (``stage_x``, ``stage_y``) if any."""
    return [Motor(name, s.id, s.model) for name, s in servo_roster(cfg, stage).items()]
