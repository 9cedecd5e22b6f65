"""A vendor-neutral motor bus: what the drive needs from any servo bus, in SI.

Positions are servo shaft angles in rad (multi-turn, signed), velocities in rad/s. A vendor
package (``robot.dynamixel``) converts to its own units at its boundary. Errors are split the way
a caller must react to them: the wire failed (:class:`ServoTransportError`, an ``OSError``: check
cables and power, maybe retry) or a servo answered that something is wrong
(:class:`ServoFaultError`: stop, read the fault, reboot the servo).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Protocol, Self

from ..config.loader import InputError


class ServoTransportError(OSError):
    """No valid answer on the bus after the bounded retries (timeout, corrupt packet, port)."""


class ServoFaultError(RuntimeError):
    """A servo reported a fault: a status-packet error number and/or Hardware Error Status bits.

    ``servo_id`` is the bus ID, ``error_number`` the status error (0 if none; 7 = Access Error,
    ...), ``hardware_error`` the raw Hardware Error Status bits and ``hardware_error_names`` their
    decoded names.
    """

    def __init__(
        self,
        servo_id: int,
        message: str,
        *,
        error_number: int = 0,
        hardware_error: int = 0,
        hardware_error_names: tuple[str, ...] = (),
    ) -> None:
        self.servo_id = servo_id
        self.error_number = error_number
        self.hardware_error = hardware_error
        self.hardware_error_names = hardware_error_names
        super().__init__(f"servo {servo_id}: {message}")


class ServoIdentityError(InputError):
    """The servo at an ID is not the model the configuration names (a configuration error)."""


@dataclass(frozen=True)
class MotorState:
    """One servo's measured state: shaft angle (rad), shaft velocity (rad/s), moving flag."""

    position: float
    velocity: float
    moving: bool


class MotorBus(Protocol):
    """The small interface the drive uses; motors are addressed by name."""

    @property
    def names(self) -> tuple[str, ...]: ...

    def connect(self) -> None:
        """Open the transport, identify the servos, put them in multi-turn position mode."""
        ...

    def close(self) -> None:
        """Torque off on every servo (best effort), then release the transport. Idempotent."""
        ...

    def set_torque(self, enabled: bool) -> None: ...

    def set_profile(self, name: str, velocity: float, acceleration: float) -> None:
        """Limit a servo's profile: shaft velocity (rad/s) and acceleration (rad/s^2)."""
        ...

    def read_state(self, names: Sequence[str] | None = None) -> dict[str, MotorState]:
        """One read of every servo's state (one bus transaction per control tick); of those
        ``names`` only, when given."""
        ...

    def write_goals(self, goals: Mapping[str, float]) -> dict[str, float]:
        """Command shaft angles (rad); returns the goals sent after the per-tick step clamp."""
        ...

    def __enter__(self) -> Self: ...

    def __exit__(self, *exc: object) -> None: ...
