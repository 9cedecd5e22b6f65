"""The x-y stage under the sample: stage position <-> servo shafts, its guards, homing and moves.

Two lead-screw axes (``config.xystage.XYStageConfig``, ``stage:`` of the robot file) on the
drive's bus: shaft = 2 pi / lead * (position - home). A position ``(x, y)`` (m) is the point of
the sample under the tip (docs/maps.md). The stage moves only while the sensor is back at its
retract pose and clear of the tissue (:class:`StageController` refuses otherwise), so a probe's
move never drags the tip across the surface or twists the sensor in the tube::

    stage = StageController(bus, stack.stage)      # bus: the drive's, with the stage's servos
    stage.start()                                  # profiles, software homing (present = home)
    stage.move_to((3e-3, -2e-3), clock, tick=0.004, clear=lambda: drive_is_back)
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping

from ..config.xystage import XYStageConfig
from ..sensor.clock import Clock
from .drive import JointLimitError
from .motors import MotorBus, MotorState
from .records.cdr import Transform

STAGE_X = "stage_x"
STAGE_Y = "stage_y"
STAGE_SERVOS = (STAGE_X, STAGE_Y)
Point = tuple[float, float]
ONE_TICK = 2.0 * math.pi / 4096  # rad: a goal sent equals the goal to this (the encoder's step)


class StageLimitError(JointLimitError):
    """A stage goal outside the configured travel."""


class StageMoveError(RuntimeError):
    """The stage did not reach its goal in time, or was asked to move with the sensor out."""


class XYAxes:
    """Pure mapping between the stage position (m) and its servo shafts (rad)."""

    def __init__(self, cfg: XYStageConfig, offsets: Mapping[str, float] | None = None) -> None:
        self.cfg = cfg
        self.offsets = dict.fromkeys(STAGE_SERVOS, 0.0)
        if offsets is not None:
            self.offsets.update({n: float(offsets[n]) for n in STAGE_SERVOS})
        self._rad_per_m = 2.0 * math.pi / cfg.lead

    def check(self, p: Point) -> None:
        """Raise StageLimitError if ``p`` is outside the travel."""
        for axis, value, (lo, hi) in zip("xy", p, self.cfg.travel, strict=True):
            if not lo - 1e-12 <= value <= hi + 1e-12:
                raise StageLimitError(
                    f"stage {axis} {value * 1e3:+.3f} mm outside "
                    f"[{lo * 1e3:g}, {hi * 1e3:g}] mm (stage.{axis}_travel_mm)"
                )

    def shafts(self, p: Point) -> dict[str, float]:
        """Servo shaft angles (rad) that put the stage at ``p``; checks the travel."""
        self.check(p)
        hx, hy = self.cfg.home
        k = self._rad_per_m
        return {
            STAGE_X: self.offsets[STAGE_X] + k * (p[0] - hx),
            STAGE_Y: self.offsets[STAGE_Y] + k * (p[1] - hy),
        }

    def position(self, shafts: Mapping[str, float]) -> Point:
        """The stage position (m) that shaft angles (rad) measure."""
        hx, hy = self.cfg.home
        k = self._rad_per_m
        return (
            hx + (shafts[STAGE_X] - self.offsets[STAGE_X]) / k,
            hy + (shafts[STAGE_Y] - self.offsets[STAGE_Y]) / k,
        )

    def profile(self) -> tuple[float, float]:
        """Each servo's (shaft velocity rad/s, acceleration rad/s^2) from the stage's limits."""
        return self.cfg.max_speed * self._rad_per_m, self.cfg.max_accel * self._rad_per_m

    def homed(self, shafts_now: Mapping[str, float]) -> XYAxes:
        """Axes whose offsets make ``shafts_now`` the configured home pose."""
        return XYAxes(self.cfg, {n: shafts_now[n] for n in STAGE_SERVOS})


class Gantry:
    """Where a stage that carries the robot (``carries: robot``) puts the robot's base for a
    stage position: ``base(point)``, and ``frames(point)``, the ``/tf`` ``world`` -> ``base`` of
    a map's probe there. :meth:`of` gives None for a stage that carries the sample."""

    def __init__(self, cfg: XYStageConfig) -> None:
        self.cfg = cfg

    @classmethod
    def of(cls, cfg: XYStageConfig | None) -> Gantry | None:
        return None if cfg is None or cfg.carries != "robot" else cls(cfg)

    def base(self, point: Point) -> tuple[float, float, float]:
        """The base frame's offset (m) with the stage at ``point``: ``x * x_direction + y *
        y_direction``."""
        (x, y), dx, dy = point, self.cfg.x_direction, self.cfg.y_direction
        bx, by, bz = (x * a + y * b for a, b in zip(dx, dy, strict=True))
        return bx, by, bz

    def frames(self, point: Point) -> list[Transform]:
        return [("world", "base", self.base(point), (0.0, 0.0, 0.0, 1.0))]


class StageController:
    """Moves of the stage over the drive's :class:`robot.motors.MotorBus` (which carries the
    stage's servos, ``robot.dynamixel.driver.DynamixelBus.from_config(..., stage=...)``)."""

    def __init__(self, bus: MotorBus, cfg: XYStageConfig) -> None:
        self.bus = bus
        self.axes = XYAxes(cfg)
        self.position: Point = cfg.home  # the last goal sent (m)
        self._tick_m = cfg.lead / 4096  # one encoder tick of travel

    def start(self) -> None:
        """Profiles and software homing: the present shafts are the configured home pose (the
        stage is at home at power-up, as the drive is). Torque is the bus's (on with it)."""
        velocity, acceleration = self.axes.profile()
        for name in STAGE_SERVOS:
            self.bus.set_profile(name, velocity, acceleration)
        state = self.bus.read_state(STAGE_SERVOS)
        self.axes = self.axes.homed({n: state[n].position for n in STAGE_SERVOS})
        self.position = self.axes.cfg.home

    def read(self) -> Point:
        """The measured stage position (m), one read of its two servos."""
        return self._at(self.bus.read_state(STAGE_SERVOS))

    def _at(self, state: Mapping[str, MotorState]) -> Point:
        return self.axes.position({n: state[n].position for n in STAGE_SERVOS})

    def follow(self, p: Point) -> Point:
        """One tick of a jog: send the goal ``p`` (m; checked against the travel), step-clamped
        by the bus; the goal sent (m). Nothing is written once the last goal sent is ``p``."""
        if p != self.position:
            self.position = self.axes.position(self.bus.write_goals(self.axes.shafts(p)))
            if max(abs(self.position[0] - p[0]), abs(self.position[1] - p[1])) < self._tick_m:
                self.position = p  # there, to the encoder's step
        return self.position

    def travel_time(self, p: Point) -> float:
        """How long a move from the last goal to ``p`` takes at the stage's speed and
        acceleration (s; both axes at once, the longer one)."""
        cfg = self.axes.cfg
        d = max(abs(p[0] - self.position[0]), abs(p[1] - self.position[1]))
        v, a = cfg.max_speed, cfg.max_accel
        if d <= v * v / a:
            return 2.0 * math.sqrt(d / a)
        return d / v + v / a

    def move_to(
        self,
        p: Point,
        clock: Clock,
        *,
        tick: float,
        clear: Callable[[], bool],
        idle: Callable[[], object] = lambda: None,
        patience: float = 2.0,
    ) -> Point:
        """Drive the stage to ``p`` (m) and wait until both axes stand still within
        ``arrived_mm`` of it; the measured position. ``clear()`` must say the sensor is back
        and free, before the move and at every tick (else :class:`StageMoveError`, the goal
        held where the stage is);
        ``idle()`` runs each tick (drain the board's stream). Raises StageLimitError before
        anything moves, StageMoveError when the stage is not there after ``patience`` times
        the planned travel time (a jam, a slipping screw), and the bus's errors (a servo fault).
        """
        goals = self.axes.shafts(p)
        deadline = clock.now() + patience * self.travel_time(p) + 10 * tick + 0.5
        arrived = self.axes.cfg.arrived
        while True:
            if not clear():
                here = self.read()
                self.bus.write_goals(self.axes.shafts(here))
                raise StageMoveError(
                    f"stage move to ({p[0] * 1e3:+.2f}, {p[1] * 1e3:+.2f}) mm stopped at "
                    f"({here[0] * 1e3:+.2f}, {here[1] * 1e3:+.2f}) mm: the sensor is not back"
                )
            sent = self.bus.write_goals(goals)
            self.position = self.axes.position(sent)
            clock.sleep(tick)
            idle()
            state = self.bus.read_state(STAGE_SERVOS)
            here = self._at(state)
            sent_all = all(abs(sent[n] - goals[n]) <= ONE_TICK for n in goals)
            still = not any(state[n].moving for n in STAGE_SERVOS)
            if sent_all and still and max(abs(here[0] - p[0]), abs(here[1] - p[1])) <= arrived:
                self.position = p
                return here
            if clock.now() > deadline:
                raise StageMoveError(
                    f"stage did not reach ({p[0] * 1e3:+.2f}, {p[1] * 1e3:+.2f}) mm in time: "
                    f"at ({here[0] * 1e3:+.2f}, {here[1] * 1e3:+.2f}) mm"
                )
