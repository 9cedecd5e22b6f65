"""The servo's motion model: pure functions of the shaft state, in ticks and seconds.

Position modes move toward the goal with a trapezoidal profile (:func:`profile_motion`; a
triangle on short moves), the velocity mode ramps to the goal velocity (:func:`velocity_motion`);
the limits come from Profile_Velocity (0 means Velocity_Limit) and Profile_Acceleration (0
means a step in velocity), converted from the control table's units by :func:`profile_limits`.
"""

from __future__ import annotations

import math
from typing import Final

from ...wire import dynamixel as tables

TICKS_PER_S_PER_VEL_UNIT: Final = tables.VELOCITY_UNIT_RPM * tables.TICKS_PER_REV / 60.0
TICKS_PER_S2_PER_ACC_UNIT: Final = tables.ACCELERATION_UNIT_RPM2 * tables.TICKS_PER_REV / 3600.0
MAX_STEP_S: Final = 1e-3
POSITION_MODES: Final = frozenset(
    {tables.MODE_POSITION, tables.MODE_EXTENDED_POSITION, tables.MODE_CURRENT_POSITION}
)
DRIVEN_MODES: Final = POSITION_MODES | {tables.MODE_VELOCITY}  # the modes that move the shaft


def profile_limits(vel_units: int, acc_units: int) -> tuple[float, float]:
    """(vmax ticks/s, amax ticks/s^2) from the profile's velocity and acceleration in the
    table's units (0: unlimited, inf)."""
    vmax = vel_units * TICKS_PER_S_PER_VEL_UNIT if vel_units else math.inf
    amax = acc_units * TICKS_PER_S2_PER_ACC_UNIT if acc_units else math.inf
    return vmax, amax


def profile_motion(
    pos: float, vel: float, goal: float, vmax: float, amax: float, dt: float
) -> tuple[float, float]:
    """Shaft position (ticks) and velocity (ticks/s) after ``dt`` s of moving toward ``goal``.

    The profile of position mode: the speed is at most ``vmax`` and, with a finite ``amax``, at
    most the speed from which the shaft can still stop at the goal (``sqrt(2 amax |e|)``); the
    velocity changes by at most ``amax`` per second (at once if ``amax`` is infinite). Explicit
    Euler in steps of at most 1 ms; a step that reaches or crosses the goal ends exactly on it
    with zero velocity. Pure (the servo's hot path, about one call per moving servo per tick).
    """
    unlimited_acceleration = math.isinf(amax)
    remaining = dt
    while remaining > 0:
        h = min(remaining, MAX_STEP_S)
        remaining -= h
        e = goal - pos
        if e == 0.0 and vel == 0.0:
            break
        speed = vmax if unlimited_acceleration else min(vmax, math.sqrt(2.0 * amax * abs(e)))
        v_des = math.copysign(speed, e)
        v = v_des if unlimited_acceleration else vel + max(-amax * h, min(amax * h, v_des - vel))
        new_pos = pos + v * h
        if abs(e) < 1e-6 or (e > 0 and new_pos >= goal) or (e < 0 and new_pos <= goal):
            return goal, 0.0  # arrived: the profile ends with zero velocity
        pos, vel = new_pos, v
    return pos, vel


def velocity_motion(
    pos: float, vel: float, target: float, amax: float, dt: float
) -> tuple[float, float]:
    """Shaft position and velocity after ``dt`` s of ramping toward ``target`` (ticks/s) at
    ``amax`` (at once if infinite), in one step."""
    dv = target - vel
    vel = target if math.isinf(amax) else vel + max(-amax * dt, min(amax * dt, dv))
    return pos + vel * dt, vel
