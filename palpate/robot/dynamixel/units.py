"""The one place where SI meets X-series units: ticks, velocity and acceleration units.

One function per direction and quantity. Positions: 4096 ticks per shaft revolution, signed
32-bit, limited to +-1 048 575 ticks in extended position mode. The SDK hands every value over
as an unsigned integer; :func:`to_signed` / :func:`to_unsigned` convert.
"""

from __future__ import annotations

import math

from ...wire import dynamixel as tables

_TICKS_PER_RAD = tables.TICKS_PER_REV / (2.0 * math.pi)
_RAD_S_PER_VELOCITY_UNIT = tables.VELOCITY_UNIT_RPM * 2.0 * math.pi / 60.0
_RAD_S2_PER_ACCELERATION_UNIT = tables.ACCELERATION_UNIT_RPM2 * 2.0 * math.pi / 3600.0


def ticks_from_rad(angle: float) -> int:
    """Shaft angle (rad) -> Goal_Position ticks; ValueError outside the multi-turn range."""
    if not math.isfinite(angle):
        raise ValueError(f"shaft angle must be finite, got {angle}")
    ticks = round(angle * _TICKS_PER_RAD)
    if abs(ticks) > tables.EXTENDED_POSITION_LIMIT:
        raise ValueError(
            f"shaft angle {angle:.3f} rad is {ticks} ticks, "
            f"beyond +-{tables.EXTENDED_POSITION_LIMIT}"
        )
    return ticks


def rad_from_ticks(ticks: int) -> float:
    """Present_Position ticks (signed) -> shaft angle in rad."""
    return ticks / _TICKS_PER_RAD


def velocity_units_from_rad_s(velocity: float) -> int:
    """Shaft speed (rad/s) -> Profile_Velocity units (0.229 rev/min), at least 1 (0 = unlimited)."""
    if not velocity > 0:
        raise ValueError(f"profile velocity must be > 0, got {velocity}")
    return max(1, round(velocity / _RAD_S_PER_VELOCITY_UNIT))


def rad_s_from_velocity_units(units: int) -> float:
    """Present_Velocity units (signed) -> shaft speed in rad/s."""
    return units * _RAD_S_PER_VELOCITY_UNIT


def acceleration_units_from_rad_s2(acceleration: float) -> int:
    """Shaft acceleration (rad/s^2) -> Profile_Acceleration units (214.577 rev/min^2), >= 1."""
    if not acceleration > 0:
        raise ValueError(f"profile acceleration must be > 0, got {acceleration}")
    return max(1, round(acceleration / _RAD_S2_PER_ACCELERATION_UNIT))


def to_signed(raw: int, size: int) -> int:
    """An unsigned value of ``size`` bytes as the SDK returns it -> two's-complement integer."""
    bits = 8 * size
    raw &= (1 << bits) - 1
    return raw - (1 << bits) if raw >= 1 << (bits - 1) else raw


def to_unsigned(value: int, size: int) -> int:
    """A signed integer -> the unsigned value of ``size`` bytes to hand to the SDK."""
    bits = 8 * size
    if not -(1 << (bits - 1)) <= value < (1 << bits):
        raise ValueError(f"{value} does not fit in {size} bytes")
    return value & ((1 << bits) - 1)
