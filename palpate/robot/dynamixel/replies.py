"""What the driver reads out of the servos' replies, and the goals' sync-write parameters: the
bytes of one tick's sync read and sync write, and the errors a status packet reports.

Pure functions over bytes and numbers; :mod:`robot.dynamixel.driver` does the transactions.
"""

from __future__ import annotations

import struct

from ...wire import dynamixel as tables
from ..motors import MotorState, ServoFaultError, ServoTransportError
from . import units

STATE_START = tables.X_SERIES_CONTROL_TABLE["Moving"][0]
"""First address of one tick's sync read: Moving .. Present_Position."""
STATE_LEN = sum(tables.X_SERIES_CONTROL_TABLE["Present_Position"]) - STATE_START
GOAL_ADDR, GOAL_LEN = tables.X_SERIES_CONTROL_TABLE["Goal_Position"]


def _state_format() -> struct.Struct:
    """Moving (u8), Present_Velocity and Present_Position (s32) out of one sync-read reply."""
    velocity = tables.X_SERIES_CONTROL_TABLE["Present_Velocity"][0] - STATE_START
    position = tables.X_SERIES_CONTROL_TABLE["Present_Position"][0] - STATE_START
    return struct.Struct(f"<B{velocity - 1}xi{position - velocity - 4}xi")


_STATE = _state_format()  # one unpack per reply instead of slices and int.from_bytes
# one servo's part of the goals' sync write: its ID, then its Goal_Position (signed)
_GOAL_PARAM = struct.Struct("<B" + {1: "b", 2: "h", 4: "i"}[GOAL_LEN])


def decode_state(servo_id: int, data: list[int]) -> MotorState:
    """One servo's part of the tick's sync read, in SI; a short or implausible reply is a
    :class:`ServoTransportError` (never a goal to start the step clamp from)."""
    if len(data) != STATE_LEN:
        # the SDK hands over what the status packet had (with its CRC bytes if short)
        raise ServoTransportError(
            f"servo {servo_id}: short reply ({len(data)} of {STATE_LEN} bytes)"
        )
    moving, velocity, position = _STATE.unpack(bytes(data))
    if abs(position) > tables.EXTENDED_POSITION_LIMIT:
        # Beyond what extended position mode can reach or be commanded to: a corrupt reply that
        # passed the CRC.
        raise ServoTransportError(
            f"servo {servo_id}: implausible present position {position} ticks"
        )
    return MotorState(
        position=units.rad_from_ticks(position),
        velocity=units.rad_s_from_velocity_units(velocity),
        moving=bool(moving),
    )


def goal_param(servo_id: int, ticks: int) -> bytes:
    """One servo's part of the goals' sync write (``ticks`` in the extended position range)."""
    return _GOAL_PARAM.pack(servo_id, ticks)


def status_fault(servo_id: int, error: int) -> ServoFaultError:
    """The fault a status packet's error byte reports (without the Alert bit's details)."""
    return ServoFaultError(
        servo_id,
        ", ".join(tables.decode_status_error(error)),
        error_number=error & 0x7F,
    )


def hardware_fault(servo_id: int, bits: int, number: int = 0) -> ServoFaultError:
    """The fault of a servo whose Hardware_Error_Status reads ``bits`` (with the status packet's
    error number ``number``, when a reply's Alert bit led to it)."""
    names = tables.decode_hardware_error(bits)
    status = tables.STATUS_ERRORS.get(number)
    message = "hardware error: " + (", ".join(names) or "none reported")
    if status:
        message += f" (and {status})"
    return ServoFaultError(
        servo_id,
        message,
        error_number=number,
        hardware_error=bits,
        hardware_error_names=names,
    )
