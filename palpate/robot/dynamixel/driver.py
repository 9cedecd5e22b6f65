"""The Dynamixel bus driver on the real ``dynamixel_sdk`` (Protocol 2.0), in SI.

:class:`DynamixelBus` satisfies :class:`robot.motors.MotorBus`. It takes its transport in the
constructor: a port path (``"/dev/ttyUSB0"``, or the pty of ``sim.dynamixel.EmulatedBus``) or an
already constructed ``dynamixel_sdk.PortHandler`` (and, optionally, an object with the SDK
packet handler's calls: the simulator's register-level path). Nothing is patched and nothing is
built behind the caller's back, so a test hands it the emulator's port.

Per control tick it makes one sync write of the goals (:meth:`DynamixelBus.write_goals`; none
where the servos hold them already) and one sync read of Moving .. Present_Position
(:meth:`DynamixelBus.read_state`), from the SDK's ``syncReadTx`` / ``readRx``: ``GroupSyncRead``
drops each status packet's error byte, whose Alert bit is how a servo reports a hardware fault.

Safety lives here: every transaction is retried a bounded number of times and then raises
:class:`~robot.motors.ServoTransportError`; a port that fails under the driver (a USB adapter
unplugged: pyserial's EIO or "readiness to read but returned no data") is counted
(``port_errors``) and opened again with a back-off (``reopens``; :mod:`robot.dynamixel.port`),
its transactions failing as transport errors meanwhile; a status error or the Alert bit raises
:class:`~robot.motors.ServoFaultError` with the decoded Hardware Error Status (never retried);
goals move at most ``max_goal_step`` per call; :meth:`close` (also leaving the ``with`` block)
turns torque off on every servo before releasing the port, whatever happened before."""

from __future__ import annotations

import contextlib
import logging
import math
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any, Self, TypeVar

import dynamixel_sdk as sdk

from ...config.schema import ServoBusConfig, XYStageConfig
from ...sensor.ports import PORT_ERRORS, open_failure
from ...wire import dynamixel as tables
from ..motors import MotorState, ServoFaultError, ServoIdentityError, ServoTransportError
from . import units
from .latency import USB_SERIAL_SYSFS, latency_warning
from .port import PortRecovery, TimedPortHandler
from .replies import (
    GOAL_ADDR,
    GOAL_LEN,
    STATE_LEN,
    STATE_START,
    decode_state,
    goal_param,
    hardware_fault,
    status_fault,
)
from .roster import Motor, bus_motors
from .stats import GOALS_WRITE, BusStats

R = TypeVar("R")
CONNECT_PATIENCE_S = 0.5
log = logging.getLogger(__name__)


class DynamixelBus:
    """X-series servos in extended position mode on one Protocol 2.0 bus."""

    def __init__(
        self,
        port: str | Any,
        motors: Sequence[Motor],
        *,
        baudrate: int = 1_000_000,
        retries: int = 3,
        timeout: float = 0.02,
        max_goal_step: float = math.radians(10.0),
        packet_handler: Any | None = None,
        usb_serial_sysfs: Path = USB_SERIAL_SYSFS,
    ) -> None:
        names = [m.name for m in motors]
        ids = [m.id for m in motors]
        if not motors or len(set(names)) != len(names) or len(set(ids)) != len(ids):
            raise ValueError(f"motors need unique names and ids, got {motors}")
        for m in motors:
            if m.model not in tables.MODEL_NUMBERS:
                raise ValueError(f"motor {m.name!r}: unknown model {m.model!r}")
        if retries < 0 or not timeout > 0 or not max_goal_step > 0:
            raise ValueError("retries must be >= 0, timeout and max_goal_step > 0")
        self._motors = {m.name: m for m in motors}
        self._by_id = {m.id: m for m in motors}
        self._ids = [m.id for m in motors]  # the sync read's parameter (made once, not per tick)
        self._subsets: dict[tuple[str, ...], list[int]] = {}
        self._port = TimedPortHandler(port, timeout * 1e3) if isinstance(port, str) else port
        # the SDK's Protocol 2.0 packet handler, or one with its calls (the simulator's
        # register-level fast path, ``sim.dynamixel.direct``): this class decides the same
        self._ph = sdk.PacketHandler(2.0) if packet_handler is None else packet_handler
        self._baudrate = baudrate
        self._retries = retries
        # every transaction of connect waits CONNECT_PATIENCE_S at least: nothing moves yet,
        # and a busy host (or an emulator starting beside it) may answer late
        self._connect_retries = max(retries, math.ceil(CONNECT_PATIENCE_S / timeout) - 1)
        self.max_goal_step = max_goal_step
        self._last_goals: dict[str, float] = {}
        self._connected = False
        self._sysfs = usb_serial_sysfs  # where Linux shows the USB adapter's latency timer
        self.recovery = PortRecovery(self._port, baudrate)  # a lost port, opened again
        self.stats = BusStats()  # retries and latency, measured (wall time)

    @classmethod
    def from_config(
        cls,
        cfg: ServoBusConfig,
        port: str | Any | None = None,
        packet_handler: Any | None = None,
        stage: XYStageConfig | None = None,
    ) -> Self:
        """The drive's three servos, and the x-y stage's two after them when ``stage`` is
        given; ``port`` overrides ``cfg.port`` (e.g. an emulator's pty), ``packet_handler``
        the SDK's (see :meth:`__init__`)."""
        return cls(
            cfg.port if port is None else port,
            bus_motors(cfg, stage),
            baudrate=cfg.baudrate,
            retries=cfg.retries,
            timeout=cfg.timeout,
            max_goal_step=cfg.max_goal_step,
            packet_handler=packet_handler,
        )

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self._motors)

    @property
    def port_handler(self) -> Any:
        return self._port

    @property
    def port_errors(self) -> int:
        """Transactions that failed in the port itself (it was lost)."""
        return self.recovery.port_errors

    @property
    def reopens(self) -> int:
        """Times a lost port was opened again."""
        return self.recovery.reopens

    # --- lifecycle ---------------------------------------------------------------------------
    def connect(self) -> None:
        """Open the port, ping and identify every servo, torque off, extended position mode.

        Raises ServoTransportError if the port cannot be opened or a servo does not answer,
        ServoIdentityError if a model number differs from the configured model, and
        ServoFaultError if a servo reports a hardware error (reboot it with :meth:`reboot`).
        """
        if self._connected:
            return
        try:
            opened = self._port.openPort() and self._port.setBaudRate(self._baudrate)
        except (OSError, ValueError) as exc:  # pyserial's SerialException is an OSError
            name = self._port.getPortName()
            raise ServoTransportError(open_failure("servo bus", name, exc)) from exc
        if not opened:
            raise ServoTransportError(f"cannot open {self._port.getPortName()}")
        warning = latency_warning(str(self._port.getPortName()), self._sysfs)
        if warning:
            log.warning("%s", warning)
        self._connected = True
        retries, self._retries = self._retries, self._connect_retries
        try:
            for m in self._motors.values():
                model = self.ping(m.name)
                if model != tables.MODEL_NUMBERS[m.model]:
                    found = tables.MODEL_NAMES.get(model, f"model number {model}")
                    raise ServoIdentityError(
                        f"servo {m.id} ({m.name}) is a {found}, the configuration says {m.model}"
                    )
            self.check_hardware_errors()
            self.set_torque(False)
            for m in self._motors.values():
                if self.read_item(m.name, "Operating_Mode") != tables.MODE_EXTENDED_POSITION:
                    self.write_item(m.name, "Operating_Mode", tables.MODE_EXTENDED_POSITION)
        except BaseException:
            self.close()  # its torque-off names its own retries
            raise
        finally:
            self._retries = retries

    def close(self) -> None:
        """Torque off on every servo (best effort, each tried), then close the port."""
        if not self._connected:
            return
        try:
            for m in self._motors.values():

                def torque_off(servo_id: int = m.id) -> tuple[None, int, int]:
                    result, error = self._ph.write1ByteTxRx(self._port, servo_id, 64, 0)
                    return None, result, error

                # keep going on failure: the other servos must still be released
                with contextlib.suppress(ServoTransportError):
                    self._transact(f"torque off {m.name}", torque_off, servo_id=None, retries=1)
        finally:
            self._port.closePort()
            self._connected = False
            self._last_goals.clear()

    def __enter__(self) -> Self:
        self.connect()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- single-servo operations -------------------------------------------------------------
    def ping(self, name: str, retries: int | None = None) -> int:
        """The model number the servo answers with (``retries``: the bus's unless given)."""
        m = self._motors[name]
        model = self._transact(
            f"ping {name}", lambda: self._ph.ping(self._port, m.id), m.id, retries
        )
        return int(model)

    def read_item(self, name: str, item: str) -> int:
        """Read one control-table item (signed where the hardware is)."""
        m = self._motors[name]
        address, size = tables.X_SERIES_CONTROL_TABLE[item]
        data = self._transact(
            f"read {item} of {name}",
            lambda: self._ph.readTxRx(self._port, m.id, address, size),
            m.id,
        )
        raw = int.from_bytes(bytes(data[:size]), "little")
        return units.to_signed(raw, size) if item in tables.SIGNED else raw

    def write_item(self, name: str, item: str, value: int) -> None:
        """Write one control-table item and wait for the servo's status packet."""
        m = self._motors[name]
        address, size = tables.X_SERIES_CONTROL_TABLE[item]
        payload = list(units.to_unsigned(int(value), size).to_bytes(size, "little"))

        def call() -> tuple[None, int, int]:
            result, error = self._ph.writeTxRx(self._port, m.id, address, size, payload)
            return None, result, error

        self._transact(f"write {item}={value} to {name}", call, m.id)

    def read_hardware_error(self, name: str) -> int:
        """Hardware_Error_Status bits of one servo (does not raise on the Alert bit)."""
        m = self._motors[name]
        data = self._transact(
            f"read Hardware_Error_Status of {name}",
            lambda: self._ph.readTxRx(self._port, m.id, 70, 1),
            servo_id=None,
        )
        return int(data[0])

    def check_hardware_errors(self) -> None:
        """Raise ServoFaultError for the first servo whose Hardware_Error_Status is non-zero."""
        for m in self._motors.values():
            bits = self.read_hardware_error(m.name)
            if bits:
                raise hardware_fault(m.id, bits)

    def reboot(self, name: str) -> None:
        """Reboot one servo: clears its hardware error, torque off, turn count lost."""
        m = self._motors[name]

        def call() -> tuple[None, int, int]:
            result, error = self._ph.reboot(self._port, m.id)
            return None, result, error

        self._transact(f"reboot {name}", call, servo_id=None)
        self._last_goals.pop(name, None)

    # --- bus-wide operations -----------------------------------------------------------------
    def set_torque(self, enabled: bool) -> None:
        """Torque on or off on every servo; on, the goal step clamp starts from where they are."""
        for m in self._motors.values():
            self.write_item(m.name, "Torque_Enable", int(enabled))
        if enabled:
            state = self.read_state()
            self._last_goals = {name: s.position for name, s in state.items()}
        else:
            self._last_goals.clear()

    def set_profile(self, name: str, velocity: float, acceleration: float) -> None:
        """Profile_Velocity and Profile_Acceleration of one servo, from rad/s and rad/s^2."""
        self.write_item(
            name, "Profile_Acceleration", units.acceleration_units_from_rad_s2(acceleration)
        )
        self.write_item(name, "Profile_Velocity", units.velocity_units_from_rad_s(velocity))

    def read_state(self, names: Sequence[str] | None = None) -> dict[str, MotorState]:
        """One sync read of Moving .. Present_Position of every servo (of ``names`` only, when
        given: the drive's three on a bus that also carries the x-y stage)."""
        ids = self._ids if names is None else self._subset(names)
        replies = self._transact(
            "sync read of present state", lambda: self._sync_read_state(ids), None
        )
        out: dict[str, MotorState] = {}
        for servo_id, (data, error) in replies.items():
            self._raise_for_status(servo_id, error)
            out[self._by_id[servo_id].name] = decode_state(servo_id, data)
        return out

    def _subset(self, names: Sequence[str]) -> list[int]:
        """The bus IDs of ``names`` (made once per subset, not per tick)."""
        key = tuple(names)
        if key not in self._subsets:
            self._subsets[key] = [self._motors[n].id for n in key]
        return self._subsets[key]

    def _sync_read_state(self, ids: list[int]) -> tuple[dict[int, tuple[list[int], int]], int, int]:
        """One attempt of :meth:`read_state`: the sync read and every servo's reply, by ID."""
        result = self._ph.syncReadTx(self._port, STATE_START, STATE_LEN, ids, len(ids), False)
        replies: dict[int, tuple[list[int], int]] = {}
        if result != sdk.COMM_SUCCESS:
            return replies, result, 0
        for servo_id in ids:
            data, result, error = self._ph.readRx(self._port, servo_id, STATE_LEN)
            if result != sdk.COMM_SUCCESS:
                return replies, result, 0
            replies[servo_id] = (data, error)
        return replies, result, 0

    def write_goals(self, goals: Mapping[str, float]) -> dict[str, float]:
        """One sync write of shaft-angle goals (rad), each clamped to ``max_goal_step`` from the
        last goal sent; returns them. Torque must be on."""
        if not self._last_goals:
            raise RuntimeError("write_goals needs torque on (call set_torque(True) first)")
        sent: dict[str, float] = {}
        param: list[int] = []
        for name, goal in goals.items():
            m = self._motors[name]
            last = self._last_goals.get(name)
            if last is None:  # rebooted since torque went on: its torque is off
                raise ServoFaultError(m.id, f"{name}: torque off since its reboot")
            step = max(-self.max_goal_step, min(self.max_goal_step, goal - last))
            ticks = units.ticks_from_rad(last + step)
            sent[name] = units.rad_from_ticks(ticks)
            param += goal_param(m.id, ticks)  # ticks_from_rad keeps it in range

        if all(self._last_goals[n] == g for n, g in sent.items()):
            return sent  # a rest, a hold: 40 % of a campaign's ticks send nothing

        def call() -> tuple[None, int, int]:
            result = self._ph.syncWriteTxOnly(self._port, GOAL_ADDR, GOAL_LEN, param, len(param))
            return None, result, 0

        self._transact(GOALS_WRITE, call, servo_id=None)
        self._last_goals.update(sent)
        return sent

    # --- the retry loop and error decoding -----------------------------------------------------
    def _transact(
        self,
        what: str,
        call: Callable[[], tuple[R, int, int]],
        servo_id: int | None,
        retries: int | None = None,
    ) -> R:
        """Run ``call`` -> (value, comm result, status error) up to 1 + retries times.

        Transport failures are retried; a status error from ``servo_id`` raises at once.
        ``servo_id=None`` leaves the error byte to the caller.
        """
        if not self._connected:
            raise ServoTransportError(f"{what}: the bus is not connected")
        attempts = 1 + (self._retries if retries is None else retries)
        result = sdk.COMM_TX_FAIL
        stats, start = self.stats, time.monotonic()
        for attempt in range(attempts):
            if not self.recovery.ready():
                break
            stats.retries += attempt > 0
            sent = time.monotonic()
            try:
                value, result, error = call()
            except PORT_ERRORS as exc:  # the port failed (not a reply: the device itself)
                self._port.is_using = False
                self.recovery.lose(exc)
                continue
            if result == sdk.COMM_SUCCESS:
                now = time.monotonic()
                stats.answered(now - sent, now - start)
                if servo_id is not None:
                    self._raise_for_status(servo_id, error)
                return value
            self._port.is_using = False  # the SDK leaves it set after some failures
        stats.failed(what)
        if self.recovery.lost:
            name = self._port.getPortName()
            lost = self.recovery.lost
            raise ServoTransportError(f"{what}: port {name} lost ({lost}), reopening")
        reason = self._ph.getTxRxResult(result)
        raise ServoTransportError(f"{what}: {reason} ({attempts} attempts)")

    def _raise_for_status(self, servo_id: int, error: int) -> None:
        if not error:
            return
        if error & tables.ALERT_BIT:
            bits = self.read_hardware_error(self._by_id[servo_id].name)
            raise hardware_fault(servo_id, bits, error & 0x7F)
        raise status_fault(servo_id, error)
