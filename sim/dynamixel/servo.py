"""A stateful X-series servo: its control table in memory, access rules, and profiled motion.

The servo is driven by :class:`sim.dynamixel.bus.EmulatedBus` (which decodes packets) and moves
on the simulator's time: :meth:`EmulatedServo.advance_to` integrates the motion up to a time in
seconds, called from the bus on every ``VirtualClock`` advance or, in real-time mode, with wall
time before every packet.

What it models (addresses and defaults from :mod:`wire.dynamixel`, the one module of
``robot/`` that ``sim/`` may import: a pure-data hardware fact shared with the driver):

* every item of the X-series table, little-endian, signed where the hardware is signed;
  read-only items, items a model lacks, partial items and the EEPROM area (address < 64) while
  torque is on answer the documented error numbers (Access, Data Length, Data Range, Limit);
* position modes 3 (0..4095 within the position limits), 4 (multi-turn, +-1 048 575) and
  5 (treated as 4), velocity mode 1; motion toward the goal with Profile_Velocity (0 means
  Velocity_Limit) and Profile_Acceleration (0 means a step in velocity): a trapezoid, or a
  triangle on short moves; Present_Position/Velocity, Moving, Moving_Status, Realtime_Tick;
* Hardware_Error_Status: bits raised by fault injection; a bit that is in ``Shutdown`` turns
  torque off and keeps it off until reboot; the bus sets the Alert bit (0x80) in every reply;
* reboot and factory reset: RAM back to power-on values, hardware error cleared; the turn count
  is lost as on the real servo (Present_Position comes back within one turn);
* fault injection: dropped replies, replies with a corrupt CRC, hardware error bits, a stall
  (the shaft stops while the goal differs; an Overload error follows after
  ``overload_after_s`` as the real overload detection would).

Simplifications: Return_Delay_Time and baud rate are stored but not simulated (replies are
immediate); on torque-on the goal is set to the present position; PWM/current modes hold still;
the indirect address area is not modelled.
"""

from __future__ import annotations

import bisect
import math
import struct
import threading
from collections.abc import Callable
from typing import Final

from wire import dynamixel as tables

_TICKS_PER_S_PER_VEL_UNIT: Final = tables.VELOCITY_UNIT_RPM * tables.TICKS_PER_REV / 60.0
_TICKS_PER_S2_PER_ACC_UNIT: Final = tables.ACCELERATION_UNIT_RPM2 * tables.TICKS_PER_REV / 3600.0
_MAX_STEP_S: Final = 1e-3
_POSITION_MODES: Final = frozenset(
    {tables.MODE_POSITION, tables.MODE_EXTENDED_POSITION, tables.MODE_CURRENT_POSITION}
)
_DRIVEN_MODES: Final = _POSITION_MODES | {tables.MODE_VELOCITY}  # the modes that move the shaft


def _model_name(model: str | int) -> str:
    if isinstance(model, int):
        if model not in tables.MODEL_NAMES:
            raise ValueError(f"unknown model number {model}; known: {sorted(tables.MODEL_NAMES)}")
        return tables.MODEL_NAMES[model]
    if model not in tables.MODEL_NUMBERS:
        raise ValueError(f"unknown model {model!r}; known: {sorted(tables.MODEL_NUMBERS)}")
    return model


_Unpack = Callable[[bytes | bytearray, int], tuple[int]]
_Pack = Callable[[bytearray, int, int], None]
_UNSIGNED_FORMATS: Final = {1: "<B", 2: "<H", 4: "<I"}


def _unpacker(name: str, size: int) -> _Unpack:
    """Reads an item's value, signed where the hardware is (``struct``: no slice, no copy)."""
    fmt = _UNSIGNED_FORMATS[size]
    return struct.Struct(fmt.lower() if name in tables.SIGNED else fmt).unpack_from


# The table looked up once, not per access (tens of item accesses per control tick):
# name -> (address, reader); name -> (address, writer of the value masked to its size, mask).
_READERS: Final[dict[str, tuple[int, _Unpack]]] = {
    name: (address, _unpacker(name, size))
    for name, (address, size) in tables.X_SERIES_CONTROL_TABLE.items()
}
_WRITERS: Final[dict[str, tuple[int, _Pack, int]]] = {
    name: (address, struct.Struct(_UNSIGNED_FORMATS[size]).pack_into, (1 << (8 * size)) - 1)
    for name, (address, size) in tables.X_SERIES_CONTROL_TABLE.items()
}


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
        h = min(remaining, _MAX_STEP_S)
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


class EmulatedServo:
    """One X-series servo. Thread-safe: every public method takes the servo's lock."""

    def __init__(
        self,
        servo_id: int = 1,
        model: str | int = "XM430-W350",
        *,
        position_ticks: float = 0.0,
        overload_after_s: float | None = 1.0,
    ) -> None:
        if not 0 <= servo_id <= 252:
            raise ValueError(f"servo id must be in 0..252, got {servo_id}")
        self.model = _model_name(model)
        self.model_number = tables.MODEL_NUMBERS[self.model]
        self._table = tables.control_table(self.model)
        self._items = sorted((a, s, n) for n, (a, s) in self._table.items())
        self._starts = [a for a, _, _ in self._items]
        # (address, size) of a whole item -> the item: a write of exactly one item, the usual
        # case, needs no search for the items it overlaps
        self._whole = {(a, size): (a, size, n) for a, size, n in self._items}
        self._covered = bytearray(tables.TABLE_SIZE)  # 1 where an item of the table lives
        for a, size, _ in self._items:
            self._covered[a : a + size] = b"\x01" * size
        self._lock = threading.RLock()
        self.memory = bytearray(tables.TABLE_SIZE)
        self._reset_items(eeprom=True, keep=())
        self._set("ID", servo_id)
        self._pos = float(position_ticks)  # shaft position, ticks (Present = pos + Homing_Offset)
        self._vel = 0.0  # ticks/s
        self._t = 0.0
        self._registered: tuple[int, bytes] | None = None
        self._stalled = False
        self._stall_time = 0.0
        self.overload_after_s = overload_after_s
        self._drop = 0
        self._corrupt = 0
        self._refresh()

    # --- raw item access -------------------------------------------------------------------
    def _get(self, name: str) -> int:
        address, unpack = _READERS[name]
        return unpack(self.memory, address)[0]

    def _set(self, name: str, value: int) -> None:
        address, pack, mask = _WRITERS[name]
        pack(self.memory, address, int(value) & mask)

    def _reset_items(self, *, eeprom: bool, keep: tuple[str, ...]) -> None:
        defaults = tables.MODEL_DEFAULTS[self.model]
        for name, (address, _) in self._table.items():
            if (address < tables.EEPROM_END and not eeprom) or name in keep:
                continue
            self._set(name, defaults.get(name, 0))

    def item(self, name: str) -> int:
        """The current value of a control-table item (signed where the hardware is)."""
        with self._lock:
            return self._get(name)

    # --- the simulation hooks --------------------------------------------------------------
    @property
    def id(self) -> int:
        with self._lock:
            return self.memory[7]

    @property
    def position_ticks(self) -> int:
        """Present_Position: what a read returns (shaft position + Homing_Offset)."""
        with self._lock:
            return self._get("Present_Position")

    @property
    def velocity_ticks_per_s(self) -> float:
        with self._lock:
            return self._vel

    @property
    def torque_enabled(self) -> bool:
        with self._lock:
            return self.memory[64] == 1

    @property
    def hardware_error(self) -> int:
        with self._lock:
            return self.memory[70]

    def set_stalled(self, stalled: bool) -> None:
        """Block the shaft (something in the way): it stops while the goal may differ."""
        with self._lock:
            self._stalled = stalled
            self._stall_time = 0.0
            if stalled:
                self._vel = 0.0
            self._refresh()

    def raise_hardware_error(self, bits: int) -> None:
        """Set Hardware_Error_Status bits; bits in ``Shutdown`` turn torque off until reboot."""
        with self._lock:
            self._set("Hardware_Error_Status", self._get("Hardware_Error_Status") | bits)
            if bits & self._get("Shutdown"):
                self._set("Torque_Enable", 0)
                self._vel = 0.0
            self._refresh()

    def drop_replies(self, count: int = 1) -> None:
        """Send no status packet for the next ``count`` replies (as a servo that is off)."""
        with self._lock:
            self._drop = count

    def corrupt_replies(self, count: int = 1) -> None:
        """Send the next ``count`` status packets with a wrong CRC."""
        with self._lock:
            self._corrupt = count

    def clear_faults(self) -> None:
        """Remove injected reply faults and the stall (hardware errors need a reboot)."""
        with self._lock:
            self._drop = self._corrupt = 0
            self._stalled = False
            self._stall_time = 0.0

    def take_reply_fault(self) -> str | None:
        """For the bus: ``"drop"``, ``"corrupt"`` or None for the reply about to be sent."""
        with self._lock:
            if self._drop > 0:
                self._drop -= 1
                return "drop"
            if self._corrupt > 0:
                self._corrupt -= 1
                return "corrupt"
            return None

    # --- instructions ----------------------------------------------------------------------
    def read(self, address: int, length: int) -> tuple[int, bytes]:
        """``(error number, data)`` for a Read of ``length`` bytes at ``address``."""
        with self._lock:
            if length < 1 or address < 0 or address + length > tables.TABLE_SIZE:
                return tables.ERR_ACCESS, b""
            return 0, bytes(self.memory[address : address + length])

    def check_write(self, address: int, data: bytes) -> int:
        """The error number a Write of ``data`` at ``address`` would answer (0 if allowed)."""
        with self._lock:
            end = address + len(data)
            if not data or address < 0 or end > tables.TABLE_SIZE:
                return tables.ERR_ACCESS
            torque_on = self.memory[64] == 1
            for a, size, name in self._overlapping(address, end):
                if a < address or a + size > end:
                    return tables.ERR_DATA_LENGTH
                if name in tables.READ_ONLY or (a < tables.EEPROM_END and torque_on):
                    return tables.ERR_ACCESS
                value = _READERS[name][1](data, a - address)[0]  # signed where the item is
                error = self._check_value(name, value)
                if error:
                    return error
            if 0 in self._covered[address:end]:
                return tables.ERR_ACCESS  # a byte outside every item
            return 0

    def _overlapping(self, address: int, end: int) -> list[tuple[int, int, str]]:
        """The items that share a byte with ``[address, end)``, in address order."""
        whole = self._whole.get((address, end - address))
        if whole is not None:
            return [whole]
        i = max(bisect.bisect_right(self._starts, address) - 1, 0)
        j = bisect.bisect_left(self._starts, end, lo=i)
        return [it for it in self._items[i:j] if it[0] + it[1] > address]

    def _check_value(self, name: str, value: int) -> int:
        bounds = tables.VALUE_RANGES.get(name)
        if bounds is not None and not bounds[0] <= value <= bounds[1]:
            return tables.ERR_DATA_RANGE
        if name == "Operating_Mode" and value not in tables.OPERATING_MODES[self.model]:
            return tables.ERR_DATA_RANGE
        if (
            name == "Torque_Enable"
            and value == 1
            and self._get("Hardware_Error_Status") & self._get("Shutdown")
        ):
            return tables.ERR_RESULT_FAIL
        if name == "Goal_Position":
            mode = self._get("Operating_Mode")
            if mode == tables.MODE_POSITION:
                lo, hi = self._get("Min_Position_Limit"), self._get("Max_Position_Limit")
            else:
                lo, hi = -tables.EXTENDED_POSITION_LIMIT, tables.EXTENDED_POSITION_LIMIT
            if not lo <= value <= hi:
                return tables.ERR_DATA_LIMIT
        if name == "Goal_Velocity" and abs(value) > self._get("Velocity_Limit"):
            return tables.ERR_DATA_LIMIT
        return 0

    def write(self, address: int, data: bytes) -> int:
        """Apply a Write; returns the error number (nothing is written unless it is 0)."""
        with self._lock:
            error = self.check_write(address, data)
            if error:
                return error
            end = address + len(data)
            if self.memory[address:end] == data:
                return 0  # the same bytes again (a streamed goal at rest): nothing changes
            before_torque = self.memory[64]
            before_mode = self.memory[11]
            for a, size, _ in self._overlapping(address, end):
                self.memory[a : a + size] = data[a - address : a - address + size]
            if self.memory[64] != before_torque:
                self._vel = 0.0
                if self.memory[64] == 1:
                    self._set("Goal_Position", self._get("Present_Position"))
            if self.memory[11] != before_mode and self.memory[11] == tables.MODE_POSITION:
                self._pos = self._pos % tables.TICKS_PER_REV
            self._refresh()
            return 0

    def write_unanswered(self, address: int, data: bytes) -> None:
        """A write whose error number no one receives (Sync Write, Bulk Write).

        Bytes equal to those in memory change nothing whether or not :meth:`write` would allow
        them, so they skip its checks: a goal streamed at 250 Hz to a servo at rest.
        """
        with self._lock:
            if self.memory[address : address + len(data)] != data:
                self.write(address, data)

    def reg_write(self, address: int, data: bytes) -> int:
        """Store a write for the next Action; returns the error number."""
        with self._lock:
            error = self.check_write(address, data)
            if not error:
                self._registered = (address, bytes(data))
                self._set("Registered_Instruction", 1)
            return error

    def action(self) -> int:
        """Execute the registered write (Result Fail if there is none)."""
        with self._lock:
            if self._registered is None:
                return tables.ERR_RESULT_FAIL
            address, data = self._registered
            self._registered = None
            self._set("Registered_Instruction", 0)
            return self.write(address, data)

    def reboot(self) -> None:
        """RAM to power-on values, hardware error cleared, turn count lost."""
        with self._lock:
            self._reset_items(eeprom=False, keep=())
            self._power_cycle()

    def factory_reset(self, option: int) -> int:
        """0xFF: everything; 0x01: all but ID; 0x02: all but ID and baud rate."""
        with self._lock:
            keep = {0xFF: (), 0x01: ("ID",), 0x02: ("ID", "Baud_Rate")}.get(option)
            if keep is None:
                return tables.ERR_DATA_RANGE
            self._reset_items(eeprom=True, keep=keep)
            self._power_cycle()
            return 0

    def clear_multi_turn(self) -> int:
        """Clear instruction: bring the position within one turn (only while stopped)."""
        with self._lock:
            if self._vel != 0.0:
                return tables.ERR_RESULT_FAIL
            self._pos = self._pos % tables.TICKS_PER_REV
            if self.memory[64] == 1:
                self._set("Goal_Position", round(self._pos) + self._get("Homing_Offset"))
            self._refresh()
            return 0

    def _power_cycle(self) -> None:
        self._registered = None
        self._vel = 0.0
        self._pos = self._pos % tables.TICKS_PER_REV
        self._stall_time = 0.0
        self._refresh()

    # --- motion ----------------------------------------------------------------------------
    def advance_to(self, t: float) -> None:
        """Integrate the motion up to time ``t`` (s); earlier times only refresh registers."""
        with self._lock:
            dt = t - self._t
            if dt > 0:
                self._t = t
                before = (self._pos, self._vel, self._stalled)
                self._integrate(dt)
                if (self._pos, self._vel, self._stalled) == before and not self._stalled:
                    # at rest: only the clock register moves
                    self._set("Realtime_Tick", int(self._t * 1000.0) % 32768)
                    return
            self._refresh()

    def _limits(self) -> tuple[float, float]:
        vel_units = self._get("Profile_Velocity") or self._get("Velocity_Limit")
        vmax = vel_units * _TICKS_PER_S_PER_VEL_UNIT if vel_units else math.inf
        acc_units = self._get("Profile_Acceleration")
        amax = acc_units * _TICKS_PER_S2_PER_ACC_UNIT if acc_units else math.inf
        return vmax, amax

    def _integrate(self, dt: float) -> None:
        mode = self.memory[11]
        if self.memory[64] != 1 or mode not in _DRIVEN_MODES:
            self._vel = 0.0
            return
        if mode in _POSITION_MODES and self._vel == 0.0 and not self._stalled:
            goal_now = self._get("Goal_Position") - self._get("Homing_Offset")
            if goal_now == self._pos:
                return  # at rest on its goal (most servos, most ticks)
        vmax, amax = self._limits()
        if self._stalled:
            self._vel = 0.0
            goal = self._get("Goal_Position") - self._get("Homing_Offset")
            if mode in _POSITION_MODES and abs(goal - self._pos) > 0.5:
                self._stall_time += dt
                limit = self.overload_after_s
                if limit is not None and self._stall_time >= limit:
                    self.raise_hardware_error(tables.HW_OVERLOAD)
            return
        if mode == tables.MODE_VELOCITY:
            target: float = self._get("Goal_Velocity") * _TICKS_PER_S_PER_VEL_UNIT
            dv = target - self._vel
            self._vel = (
                target if math.isinf(amax) else self._vel + max(-amax * dt, min(amax * dt, dv))
            )
            self._pos += self._vel * dt
            return
        goal_f = float(self._get("Goal_Position") - self._get("Homing_Offset"))
        self._pos, self._vel = profile_motion(self._pos, self._vel, goal_f, vmax, amax, dt)

    def _refresh(self) -> None:
        present = round(self._pos) + self._get("Homing_Offset")
        self._set("Present_Position", present)
        self._set("Position_Trajectory", present)
        vel_units = round(self._vel / _TICKS_PER_S_PER_VEL_UNIT)
        self._set("Present_Velocity", vel_units)
        self._set("Velocity_Trajectory", vel_units)
        moving = abs(vel_units) > self._get("Moving_Threshold") or (self._vel != 0.0)
        self._set("Moving", int(moving))
        in_position = abs(self._get("Goal_Position") - present) <= 1 or self.memory[64] == 0
        vmax, amax = self._limits()
        profile = (0b01 if math.isinf(amax) else 0b11) if not math.isinf(vmax) else 0b00
        status = int(in_position) | (0b10 if moving else 0) | (profile << 4)
        self._set("Moving_Status", status)
        self._set("Realtime_Tick", int(self._t * 1000.0) % 32768)
        loaded = self._stalled and self.memory[64] == 1
        self._set("Present_Current", self._get("Current_Limit") if loaded else 0)
