"""A stateful X-series servo: its control table in memory, access rules, and profiled motion.

The servo is driven by :class:`sim.dynamixel.bus.EmulatedBus` (which decodes packets) and moves
on the simulator's time: :meth:`EmulatedServo.advance_to` integrates the motion up to a time in
seconds, called from the bus on every ``VirtualClock`` advance or, in real-time mode, with wall
time before every packet.

What it models (addresses and defaults from the control table :mod:`wire.dynamixel`, the
hardware fact the driver in ``robot/`` reads too; ``sim/`` imports ``wire/``, never ``robot/``):

* every item of the X-series table, little-endian, signed where the hardware is signed;
  read-only items, items a model lacks, partial items and the EEPROM area (address < 64) while
  torque is on answer the documented error numbers (Access, Data Length, Data Range, Limit,
  Result Fail) (:mod:`sim.dynamixel.registers`);
* position modes 3 (0..4095 within the position limits), 4 (multi-turn, +-1 048 575) and
  5 (treated as 4), velocity mode 1; motion toward the goal with Profile_Velocity (0 means
  Velocity_Limit) and Profile_Acceleration (0 means a step in velocity): a trapezoid, or a
  triangle on short moves (:mod:`sim.dynamixel.motion`); Present_Position/Velocity, Moving,
  Moving_Status, Realtime_Tick;
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

import math
import threading
from collections.abc import Callable
from typing import Final

from ...wire import dynamixel as tables
from .motion import (
    DRIVEN_MODES,
    POSITION_MODES,
    TICKS_PER_S_PER_VEL_UNIT,
    profile_limits,
    profile_motion,
    velocity_motion,
)
from .registers import OPERATING_MODE, TORQUE_ENABLE, ControlTable, model_name

_ID: Final = tables.X_SERIES_CONTROL_TABLE["ID"][0]
_HARDWARE_ERROR: Final = tables.X_SERIES_CONTROL_TABLE["Hardware_Error_Status"][0]


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
        self.model = model_name(model)
        self.model_number = tables.MODEL_NUMBERS[self.model]
        self._regs = ControlTable(self.model)
        self.memory = self._regs.memory  # the bus reads one-byte items here without the lock
        self._get: Callable[[str], int] = self._regs.get
        self._set: Callable[[str, int], None] = self._regs.set
        self._lock = threading.RLock()
        self._regs.reset(eeprom=True, keep=())
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

    # --- item access -------------------------------------------------------------------------
    def item(self, name: str) -> int:
        """The current value of a control-table item (signed where the hardware is)."""
        with self._lock:
            return self._get(name)

    # --- the simulation hooks --------------------------------------------------------------
    @property
    def id(self) -> int:
        with self._lock:
            return self.memory[_ID]

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
            return self.memory[TORQUE_ENABLE] == 1

    @property
    def hardware_error(self) -> int:
        with self._lock:
            return self.memory[_HARDWARE_ERROR]

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
            return self._regs.read(address, length)

    def check_write(self, address: int, data: bytes) -> int:
        """The error number a Write of ``data`` at ``address`` would answer (0 if allowed)."""
        with self._lock:
            return self._regs.check_write(address, data)

    def write(self, address: int, data: bytes) -> int:
        """Apply a Write; returns the error number (nothing is written unless it is 0)."""
        with self._lock:
            error = self.check_write(address, data)
            if error:
                return error
            if self.memory[address : address + len(data)] == data:
                return 0  # the same bytes again (a streamed goal at rest): nothing changes
            before_torque = self.memory[TORQUE_ENABLE]
            before_mode = self.memory[OPERATING_MODE]
            self._regs.store(address, data)
            if self.memory[TORQUE_ENABLE] != before_torque:
                self._vel = 0.0
                if self.memory[TORQUE_ENABLE] == 1:
                    self._set("Goal_Position", self._get("Present_Position"))
            mode = self.memory[OPERATING_MODE]
            if mode != before_mode and mode == tables.MODE_POSITION:
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
            self._regs.reset(eeprom=False, keep=())
            self._power_cycle()

    def factory_reset(self, option: int) -> int:
        """0xFF: everything; 0x01: all but ID; 0x02: all but ID and baud rate."""
        with self._lock:
            keep = {0xFF: (), 0x01: ("ID",), 0x02: ("ID", "Baud_Rate")}.get(option)
            if keep is None:
                return tables.ERR_DATA_RANGE
            self._regs.reset(eeprom=True, keep=keep)
            self._power_cycle()
            return 0

    def clear_multi_turn(self) -> int:
        """Clear instruction: bring the position within one turn (only while stopped)."""
        with self._lock:
            if self._vel != 0.0:
                return tables.ERR_RESULT_FAIL
            self._pos = self._pos % tables.TICKS_PER_REV
            if self.memory[TORQUE_ENABLE] == 1:
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
        return profile_limits(vel_units, self._get("Profile_Acceleration"))

    def _integrate(self, dt: float) -> None:
        mode = self.memory[OPERATING_MODE]
        if self.memory[TORQUE_ENABLE] != 1 or mode not in DRIVEN_MODES:
            self._vel = 0.0
            return
        if mode in POSITION_MODES and self._vel == 0.0 and not self._stalled:
            goal_now = self._get("Goal_Position") - self._get("Homing_Offset")
            if goal_now == self._pos:
                return  # at rest on its goal (most servos, most ticks)
        vmax, amax = self._limits()
        if self._stalled:
            self._hold_stalled(mode, dt)
            return
        if mode == tables.MODE_VELOCITY:
            target: float = self._get("Goal_Velocity") * TICKS_PER_S_PER_VEL_UNIT
            self._pos, self._vel = velocity_motion(self._pos, self._vel, target, amax, dt)
            return
        goal_f = float(self._get("Goal_Position") - self._get("Homing_Offset"))
        self._pos, self._vel = profile_motion(self._pos, self._vel, goal_f, vmax, amax, dt)

    def _hold_stalled(self, mode: int, dt: float) -> None:
        """The shaft held still for ``dt``; a position goal it cannot reach overloads it after
        ``overload_after_s``."""
        self._vel = 0.0
        goal = self._get("Goal_Position") - self._get("Homing_Offset")
        if mode in POSITION_MODES and abs(goal - self._pos) > 0.5:
            self._stall_time += dt
            limit = self.overload_after_s
            if limit is not None and self._stall_time >= limit:
                self.raise_hardware_error(tables.HW_OVERLOAD)

    def _refresh(self) -> None:
        present = round(self._pos) + self._get("Homing_Offset")
        self._set("Present_Position", present)
        self._set("Position_Trajectory", present)
        vel_units = round(self._vel / TICKS_PER_S_PER_VEL_UNIT)
        self._set("Present_Velocity", vel_units)
        self._set("Velocity_Trajectory", vel_units)
        moving = abs(vel_units) > self._get("Moving_Threshold") or (self._vel != 0.0)
        self._set("Moving", int(moving))
        in_position = (
            abs(self._get("Goal_Position") - present) <= 1 or self.memory[TORQUE_ENABLE] == 0
        )
        vmax, amax = self._limits()
        profile = (0b01 if math.isinf(amax) else 0b11) if not math.isinf(vmax) else 0b00
        status = int(in_position) | (0b10 if moving else 0) | (profile << 4)
        self._set("Moving_Status", status)
        self._set("Realtime_Tick", int(self._t * 1000.0) % 32768)
        loaded = self._stalled and self.memory[TORQUE_ENABLE] == 1
        self._set("Present_Current", self._get("Current_Limit") if loaded else 0)
