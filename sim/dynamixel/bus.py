"""A Dynamixel bus on a pseudo-terminal: X-series servos answering Protocol 2.0 packets.

:class:`EmulatedBus` owns a set of :class:`sim.dynamixel.servo.EmulatedServo` and, once opened, a
pty whose slave path (``bus.port``) any Dynamixel tool or the unmodified ``dynamixel_sdk`` can
open like ``/dev/ttyUSB0``. A background thread reads the pty master, splits the stream into
packets (:mod:`sim.dynamixel.protocol`) and writes the status packets back at once.

Time: with a ``sim.clock.VirtualClock`` the servos move only when the clock advances (an
``on_advance`` listener), so tests and simulated trials never wait on the wall clock; without a
clock (``palpate emulate``) they move on wall time, brought up to date before every packet.

Answers follow the e-manual: ping (unicast, and broadcast with every servo answering in ID
order), read, write, reg write / action, factory reset, reboot, clear (multi-turn), sync read,
sync write, bulk read, bulk write. Broadcast writes, sync/bulk writes and Action get no status
packet (the SDK does not wait for one after Action, so answering it would leave a stale packet
on the line); Status Return Level 0 answers only ping, 1 ping and reads, 2 everything; the Alert
bit (0x80) is set while Hardware_Error_Status is non-zero; a packet with a bad CRC addressed to a
servo gets CRC Error; an unknown instruction gets Instruction Error. Fast sync/bulk read are not
emulated (Instruction Error).

Bus timing: ideal by default (every reply at once). With ``timing`` (a
:class:`sim.dynamixel.timing.BusTiming`: baud rate, the servos' Return Delay Time, the USB
adapter's latency timer) and a virtual clock, the host gets each reply when a real U2D2 bus would
hand it over: the bus advances the clock to that time before the reply is seen (the host is
blocked on the read meanwhile). Without a clock (real time) the timing is not applied.

Layering: the control table comes from :mod:`wire.dynamixel`, the leaf the driver in ``robot/``
reads too; ``sim/`` never imports ``robot/``.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterable
from typing import NamedTuple, Self

from config.schema import ServoBusConfig
from sim.clock import VirtualClock
from sim.dynamixel import protocol
from sim.dynamixel.pty import PtyLink
from sim.dynamixel.servo import EmulatedServo
from sim.dynamixel.timing import RETURN_DELAY_UNIT_S, BusTiming
from wire import dynamixel as tables

_PING, _READ, _OTHER = 0, 1, 2  # reply kinds, compared with Status_Return_Level
_CLEAR_KEY = bytes([0x01, 0x44, 0x58, 0x4C, 0x22])
_REALTIME_POLL_S = 0.01
_ID_ADDRESS = tables.X_SERIES_CONTROL_TABLE["ID"][0]
_LEVEL_ADDRESS = tables.X_SERIES_CONTROL_TABLE["Status_Return_Level"][0]
_HW_ERROR_ADDRESS = tables.X_SERIES_CONTROL_TABLE["Hardware_Error_Status"][0]
_RETURN_DELAY_ADDRESS = tables.X_SERIES_CONTROL_TABLE["Return_Delay_Time"][0]


class Reply(NamedTuple):
    """One status packet before it is encoded: who answers, the error byte (Alert bit included),
    the parameters, and whether an injected fault corrupts it on the wire."""

    servo_id: int
    error: int
    params: bytes
    corrupt: bool = False

    def encode(self) -> bytes:
        raw = protocol.encode_status(self.servo_id, self.error, self.params)
        return raw[:-1] + bytes([raw[-1] ^ 0xFF]) if self.corrupt else raw


class EmulatedBus:
    """Servos on one emulated bus; a context manager that opens and closes the pty."""

    def __init__(
        self,
        servos: Iterable[EmulatedServo] = (),
        *,
        clock: VirtualClock | None = None,
        wall_time: Callable[[], float] = time.monotonic,
        timing: BusTiming | None = None,
    ) -> None:
        self._clock = clock
        self._wall_time = wall_time
        self.timing = timing
        self._line_free = 0.0  # bus time at which the line is idle (realistic timing)
        self._t0 = wall_time()
        self._servos: list[EmulatedServo] = []
        self._lock = threading.Lock()
        self._reader = protocol.PacketReader()
        self._link: PtyLink | None = None
        self.port = ""
        self.packets_handled = 0
        # instructions for the servo(s) the packet's ID addresses
        self._handlers: dict[int, Callable[[protocol.Packet, list[EmulatedServo]], list[Reply]]] = {
            protocol.INST_PING: self._ping,
            protocol.INST_READ: self._read,
            protocol.INST_WRITE: self._write,
            protocol.INST_REG_WRITE: self._reg_write,
            protocol.INST_ACTION: self._action,
            protocol.INST_FACTORY_RESET: self._factory_reset,
            protocol.INST_REBOOT: self._reboot,
            protocol.INST_CLEAR: self._clear,
        }
        # sync and bulk instructions name their servos in the parameters, not in the ID
        self._group_handlers: dict[int, Callable[[protocol.Packet], list[Reply]]] = {
            protocol.INST_SYNC_READ: self._sync_read,
            protocol.INST_SYNC_WRITE: self._sync_write,
            protocol.INST_BULK_READ: self._bulk_read,
            protocol.INST_BULK_WRITE: self._bulk_write,
        }
        for servo in servos:
            self.add(servo)
        if clock is not None:
            clock.on_advance(self._on_clock)

    @classmethod
    def from_config(
        cls,
        cfg: ServoBusConfig,
        *,
        clock: VirtualClock | None = None,
        timing: BusTiming | None = None,
    ) -> Self:
        """The three servos of the roller-gear drive with the IDs and models of ``cfg``."""
        servos = [
            EmulatedServo(s.id, s.model) for s in (cfg.outer_roll, cfg.inner_roll, cfg.translation)
        ]
        return cls(servos, clock=clock, timing=timing)

    # --- the servos --------------------------------------------------------------------------
    def add(self, servo: EmulatedServo) -> EmulatedServo:
        with self._lock:
            if any(s.id == servo.id for s in self._servos):
                raise ValueError(f"a servo with id {servo.id} is already on the bus")
            servo.advance_to(self.now())
            self._servos.append(servo)
        return servo

    def servo(self, servo_id: int) -> EmulatedServo:
        """The servo answering to ``servo_id`` (the hook for the simulated world)."""
        found = self._find(servo_id)
        if found is None:
            raise KeyError(f"no servo with id {servo_id} on the bus")
        return found

    @property
    def servos(self) -> tuple[EmulatedServo, ...]:
        return tuple(self._servos)

    def now(self) -> float:
        """Bus time in s: the virtual clock's, or wall time since the bus was made
        (``wall_time``, ``time.monotonic`` unless a test passes its own)."""
        if self._clock is not None:
            return self._clock.now()
        return self._wall_time() - self._t0

    def _on_clock(self, t: float) -> None:
        # answer what already arrived first, so a goal written before the advance is honoured
        self._pump()
        self._advance_all(t)

    def _advance_all(self, t: float) -> None:
        for s in self._servos:
            s.advance_to(t)

    # --- packets -----------------------------------------------------------------------------
    def handle(self, data: bytes) -> bytes:
        """Feed bytes as if they came down the wire; returns the bytes the servos answer."""
        with self._lock:
            if self._clock is None:
                self._advance_all(self.now())
            replies: list[Reply] = []
            for packet in self._reader.feed(data):
                self.packets_handled += 1
                replies += self._dispatch(packet)
            out = [r.encode() for r in replies]
            due = self._timed(len(data), replies, out)
        self._wait_until(due)
        return b"".join(out)

    def exchange(self, packet: protocol.Packet) -> list[Reply]:
        """Answer one decoded request without bytes: the status packets as :class:`Reply`
        records, in the order they would go on the wire (``sim.dynamixel.direct``)."""
        with self._lock:
            if self._clock is None:
                self._advance_all(self.now())
            self.packets_handled += 1
            replies = self._dispatch(packet)
            due = None
            if self.timing is not None:  # sizes as on the wire: encode only to count the bytes
                raw = protocol.encode(packet.servo_id, packet.instruction, packet.params)
                due = self._timed(len(raw), replies, [r.encode() for r in replies])
        self._wait_until(due)
        return replies

    # --- bus timing (sim.dynamixel.timing) ---------------------------------------------------
    def _timed(self, request_bytes: int, replies: list[Reply], raw: list[bytes]) -> float | None:
        """When the host has these replies (None: at once, or nothing to wait for)."""
        timing = self.timing
        if timing is None or self._clock is None:
            return None
        answers = []
        for reply, packet in zip(replies, raw, strict=True):
            servo = self._find(reply.servo_id)
            units = 0 if servo is None else servo.memory[_RETURN_DELAY_ADDRESS]
            answers.append((len(packet), units * RETURN_DELAY_UNIT_S))
        self._line_free, due = timing.exchange(self.now(), self._line_free, request_bytes, answers)
        return due

    def _wait_until(self, due: float | None) -> None:
        """The host waits for its reply: virtual time runs on to ``due`` (outside the locks:
        the clock's listeners, this bus among them, run during the advance)."""
        if due is None or self._clock is None:
            return
        dt = due - self._clock.now()
        if dt > 0:
            self._clock.advance(dt)

    def _dispatch(self, packet: protocol.Packet | protocol.BadPacket) -> list[Reply]:
        if isinstance(packet, protocol.BadPacket):
            target = self._find(packet.servo_id)
            return self._status(target, tables.ERR_CRC, b"", _OTHER) if target else []
        if packet.is_status:
            return []
        group_handler = self._group_handlers.get(packet.instruction)
        if group_handler is not None:
            return group_handler(packet)
        if packet.servo_id == protocol.BROADCAST_ID:
            targets = sorted(self._servos, key=lambda s: s.id)
        else:
            found = self._find(packet.servo_id)
            targets = [found] if found else []
        handler = self._handlers.get(packet.instruction)
        if handler is None:
            if packet.servo_id == protocol.BROADCAST_ID or not targets:
                return []
            return self._status(targets[0], tables.ERR_INSTRUCTION, b"", _OTHER)
        return handler(packet, targets)

    def _find(self, servo_id: int) -> EmulatedServo | None:
        for s in self._servos:
            if s.memory[_ID_ADDRESS] == servo_id:  # one byte: no lock needed
                return s
        return None

    @staticmethod
    def _status(servo: EmulatedServo, error: int, params: bytes, kind: int) -> list[Reply]:
        memory = servo.memory  # one-byte items: no lock needed
        if kind > memory[_LEVEL_ADDRESS]:
            return []
        if memory[_HW_ERROR_ADDRESS]:
            error |= tables.ALERT_BIT
        fault = servo.take_reply_fault()
        if fault == "drop":
            return []
        return [Reply(servo.id, error & 0xFF, bytes(params), fault == "corrupt")]

    # --- instruction handlers: (packet, addressed servos) -> status packets --------------------
    # (the sync and bulk handlers at the end take the packet alone)
    def _ping(self, packet: protocol.Packet, targets: list[EmulatedServo]) -> list[Reply]:
        out: list[Reply] = []
        for s in targets:
            params = protocol.u16(s.model_number) + bytes([s.item("Firmware_Version")])
            out += self._status(s, 0, params, _PING)
        return out

    def _read(self, packet: protocol.Packet, targets: list[EmulatedServo]) -> list[Reply]:
        if packet.servo_id == protocol.BROADCAST_ID or not targets:
            return []
        s = targets[0]
        if len(packet.params) != 4:
            return self._status(s, tables.ERR_DATA_LENGTH, b"", _READ)
        address, length = _word(packet.params, 0), _word(packet.params, 2)
        error, data = s.read(address, length)
        return self._status(s, error, data, _READ)

    def _write(self, packet: protocol.Packet, targets: list[EmulatedServo]) -> list[Reply]:
        return self._writes(packet, targets, EmulatedServo.write)

    def _reg_write(self, packet: protocol.Packet, targets: list[EmulatedServo]) -> list[Reply]:
        return self._writes(packet, targets, EmulatedServo.reg_write)

    def _writes(
        self,
        packet: protocol.Packet,
        targets: list[EmulatedServo],
        op: Callable[[EmulatedServo, int, bytes], int],
    ) -> list[Reply]:
        if len(packet.params) < 3:
            error = tables.ERR_DATA_LENGTH
            results = [error for _ in targets]
        else:
            address = _word(packet.params, 0)
            results = [op(s, address, packet.params[2:]) for s in targets]
        if packet.servo_id == protocol.BROADCAST_ID or not targets:
            return []
        return self._status(targets[0], results[0], b"", _OTHER)

    def _action(self, packet: protocol.Packet, targets: list[EmulatedServo]) -> list[Reply]:
        for s in targets:
            s.action()
        return []

    def _factory_reset(self, packet: protocol.Packet, targets: list[EmulatedServo]) -> list[Reply]:
        if packet.servo_id == protocol.BROADCAST_ID or not targets:
            return []  # a broadcast factory reset is ignored, as on the hardware
        s = targets[0]
        if len(packet.params) != 1:
            return self._status(s, tables.ERR_DATA_LENGTH, b"", _OTHER)
        if packet.params[0] not in (0x01, 0x02, 0xFF):
            return self._status(s, tables.ERR_DATA_RANGE, b"", _OTHER)
        reply = self._status(s, 0, b"", _OTHER)  # answered with the old ID, then reset
        s.factory_reset(packet.params[0])
        return reply

    def _reboot(self, packet: protocol.Packet, targets: list[EmulatedServo]) -> list[Reply]:
        out: list[Reply] = []
        if packet.servo_id != protocol.BROADCAST_ID and targets:
            out = self._status(targets[0], 0, b"", _OTHER)
        for s in targets:
            s.reboot()
        return out

    def _clear(self, packet: protocol.Packet, targets: list[EmulatedServo]) -> list[Reply]:
        if packet.params != _CLEAR_KEY:
            errors = [tables.ERR_DATA_RANGE for _ in targets]
        else:
            errors = [s.clear_multi_turn() for s in targets]
        if packet.servo_id == protocol.BROADCAST_ID or not targets:
            return []
        return self._status(targets[0], errors[0], b"", _OTHER)

    def _sync_read(self, packet: protocol.Packet) -> list[Reply]:
        if packet.servo_id != protocol.BROADCAST_ID or len(packet.params) < 5:
            return []
        address, length = _word(packet.params, 0), _word(packet.params, 2)
        out: list[Reply] = []
        for servo_id in packet.params[4:]:
            s = self._find(servo_id)
            if s is not None:
                error, data = s.read(address, length)
                out += self._status(s, error, data, _READ)
        return out

    def _sync_write(self, packet: protocol.Packet) -> list[Reply]:
        params = packet.params
        if packet.servo_id != protocol.BROADCAST_ID or len(params) < 4:
            return []
        address, length = _word(params, 0), _word(params, 2)
        chunk = 1 + length
        if length == 0 or (len(params) - 4) % chunk:
            return []
        for i in range(4, len(params), chunk):
            s = self._find(params[i])
            if s is not None:
                s.write_unanswered(address, params[i + 1 : i + chunk])
        return []

    def _bulk_read(self, packet: protocol.Packet) -> list[Reply]:
        params = packet.params
        if packet.servo_id != protocol.BROADCAST_ID or not params or len(params) % 5:
            return []
        out: list[Reply] = []
        for i in range(0, len(params), 5):
            s = self._find(params[i])
            if s is not None:
                error, data = s.read(_word(params, i + 1), _word(params, i + 3))
                out += self._status(s, error, data, _READ)
        return out

    def _bulk_write(self, packet: protocol.Packet) -> list[Reply]:
        params = packet.params
        if packet.servo_id != protocol.BROADCAST_ID:
            return []
        i = 0
        while i + 5 <= len(params):
            length = _word(params, i + 3)
            data = params[i + 5 : i + 5 + length]
            if length == 0 or len(data) != length:
                break
            s = self._find(params[i])
            if s is not None:
                s.write_unanswered(_word(params, i + 1), data)
            i += 5 + length
        return []

    # --- the pseudo-terminal (sim.dynamixel.pty) ---------------------------------------------
    def open(self) -> str:
        """Create the pty and start answering; returns the port path (also ``self.port``)."""
        if self._link is None:
            idle = self._catch_up if self._clock is None else None
            self._link = PtyLink(self.handle, idle, _REALTIME_POLL_S)
            self.port = self._link.port
        return self.port

    def close(self) -> None:
        """Stop the thread and close the pty (idempotent)."""
        if self._link is not None:
            self._link.close()
            self._link = None

    def __enter__(self) -> Self:
        self.open()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _catch_up(self) -> None:
        """Real-time mode, nothing on the line: the servos move on to wall time."""
        with self._lock:
            self._advance_all(self.now())

    def _pump(self) -> None:
        if self._link is not None:
            self._link.pump()


def _word(data: bytes, offset: int) -> int:
    return data[offset] | (data[offset + 1] << 8)
