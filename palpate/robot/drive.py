"""The dual roller-gear drive: joint space <-> servo shaft angles, limits, profiles, homing.

Joint space is ``JointState(roll, translation)``: the tube roll phi (rad, about the base x
axis; docs/architecture.md, Conventions) and the stage translation (m) that advances the
sensor. Three servos move it:

* ``outer_roll`` turns the outer roller gear, which carries the tube: shaft = r_o * phi;
* ``inner_roll`` turns the inner roller gear, slaved to the outer one so that the push rod and
  the sensor roll with the tube and never twist against it: shaft = r_i * phi;
* ``translation`` drives the inner gear along x: shaft = 2 pi / lead * (translation - c * phi).

``c`` (``DriveConfig.coupling_mm_per_rad``, default 0) is any translation a roll produces by
itself; it is applied in :meth:`RollerGearDrive.shafts` and undone in
:meth:`RollerGearDrive.joints` only. All angles are relative to the homing offsets: homing
(software, as on the bench) takes the present shaft angles as the configured home pose.
Shaft angles are multi-turn (extended position mode): the conversion to ticks is in
``robot.dynamixel.units`` and nowhere else.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from ..config.schema import DriveConfig
from .motors import MotorBus, MotorState

OUTER_ROLL = "outer_roll"
INNER_ROLL = "inner_roll"
TRANSLATION = "translation"
SERVOS = (OUTER_ROLL, INNER_ROLL, TRANSLATION)


class JointLimitError(ValueError):
    """A joint target outside the configured roll or translation limits."""


@dataclass(frozen=True)
class JointState:
    """Tube roll phi (rad) and stage translation (m)."""

    roll: float
    translation: float


class RollerGearDrive:
    """Pure mapping between joints and servo shafts for one :class:`DriveConfig`."""

    def __init__(self, cfg: DriveConfig, offsets: Mapping[str, float] | None = None) -> None:
        self.cfg = cfg
        self.offsets = dict.fromkeys(SERVOS, 0.0)
        if offsets is not None:
            self.offsets.update({name: float(offsets[name]) for name in SERVOS})
        self._rev_per_m = 2.0 * math.pi / cfg.lead
        self.home = JointState(cfg.home_roll, cfg.home_translation)  # read at every command

    def check(self, q: JointState) -> None:
        """Raise JointLimitError if ``q`` is outside the roll or translation limits."""
        lo, hi = self.cfg.roll_limits
        if not lo - 1e-12 <= q.roll <= hi + 1e-12:
            raise JointLimitError(
                f"roll {math.degrees(q.roll):.2f} deg outside "
                f"[{self.cfg.roll_min_deg}, {self.cfg.roll_max_deg}] deg"
            )
        lo, hi = self.cfg.translation_limits
        if not lo - 1e-12 <= q.translation <= hi + 1e-12:
            raise JointLimitError(
                f"translation {q.translation * 1e3:.3f} mm outside "
                f"[{self.cfg.translation_min_mm}, {self.cfg.translation_max_mm}] mm"
            )

    def shafts(self, q: JointState) -> dict[str, float]:
        """Servo shaft angles (rad) that put the drive at ``q``; checks the limits."""
        self.check(q)
        h = self.home
        droll = q.roll - h.roll
        dtrans = (q.translation - h.translation) - self.cfg.coupling * droll
        return {
            OUTER_ROLL: self.offsets[OUTER_ROLL] + self.cfg.outer_roll_ratio * droll,
            INNER_ROLL: self.offsets[INNER_ROLL] + self.cfg.inner_roll_ratio * droll,
            TRANSLATION: self.offsets[TRANSLATION] + self._rev_per_m * dtrans,
        }

    def joints(self, shafts: Mapping[str, float]) -> JointState:
        """The joint state that servo shaft angles (rad) measure (roll from the outer gear)."""
        h = self.home
        droll = (shafts[OUTER_ROLL] - self.offsets[OUTER_ROLL]) / self.cfg.outer_roll_ratio
        dtrans = (shafts[TRANSLATION] - self.offsets[TRANSLATION]) / self._rev_per_m
        return JointState(h.roll + droll, h.translation + dtrans + self.cfg.coupling * droll)

    def twist(self, shafts: Mapping[str, float]) -> float:
        """Inner minus outer roll angle (rad): how far the slaved inner gear lags the tube."""
        outer = (shafts[OUTER_ROLL] - self.offsets[OUTER_ROLL]) / self.cfg.outer_roll_ratio
        inner = (shafts[INNER_ROLL] - self.offsets[INNER_ROLL]) / self.cfg.inner_roll_ratio
        return inner - outer

    def profiles(self) -> dict[str, tuple[float, float]]:
        """Per servo (shaft velocity rad/s, shaft acceleration rad/s^2) from the joint limits."""
        c = self.cfg
        return {
            OUTER_ROLL: (
                c.max_roll_speed * c.outer_roll_ratio,
                c.max_roll_accel * c.outer_roll_ratio,
            ),
            INNER_ROLL: (
                c.max_roll_speed * c.inner_roll_ratio,
                c.max_roll_accel * c.inner_roll_ratio,
            ),
            TRANSLATION: (c.max_speed * self._rev_per_m, c.max_accel * self._rev_per_m),
        }

    def homed(self, shafts_now: Mapping[str, float]) -> RollerGearDrive:
        """A drive whose offsets make ``shafts_now`` the configured home pose."""
        return RollerGearDrive(self.cfg, {name: shafts_now[name] for name in SERVOS})


class DriveController:
    """Joint-space commands over a :class:`robot.motors.MotorBus`.

    ``start()`` connects, sets the velocity/acceleration profiles, homes (the drive must be at
    its home pose, as after power-up on the bench) and turns torque on. Use as a context manager
    so the bus closes (torque off) whatever happens.
    """

    def __init__(self, bus: MotorBus, cfg: DriveConfig) -> None:
        self.bus = bus
        self.drive = RollerGearDrive(cfg)
        # a bus that carries more than the drive (the x-y stage): each tick reads the drive's
        self._own = None if set(bus.names) == set(SERVOS) else SERVOS

    def start(self) -> None:
        self.bus.connect()
        for name, (velocity, acceleration) in self.drive.profiles().items():
            self.bus.set_profile(name, velocity, acceleration)
        state = self.bus.read_state()
        self.drive = self.drive.homed({n: s.position for n, s in state.items()})
        self.bus.set_torque(True)

    def command(self, q: JointState) -> JointState:
        """Send one goal (limits checked); returns the joint goal after the driver's step clamp."""
        sent = self.bus.write_goals(self.drive.shafts(q))
        return self.drive.joints(sent)

    def read(self) -> tuple[JointState, dict[str, MotorState]]:
        """Measured joints and the raw motor states (one bus read)."""
        state = self.bus.read_state(self._own)
        return self.drive.joints({n: s.position for n, s in state.items()}), state

    def close(self) -> None:
        self.bus.close()

    def __enter__(self) -> DriveController:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
