"""What X-series servos answer to each Protocol 2.0 instruction, as the e-manual says: ping
(unicast, and broadcast with every servo answering in ID order), read, write, reg write / action,
factory reset, reboot, clear (multi-turn), sync read, sync write, bulk read, bulk write.

Broadcast writes, sync/bulk writes and Action get no status packet; Status Return Level 0 answers
only ping, 1 ping and reads, 2 everything; the Alert bit (0x80) is set while
Hardware_Error_Status is non-zero; a packet with a bad CRC addressed to a servo gets CRC Error;
an unknown instruction gets Instruction Error (fast sync/bulk read are not emulated).

:class:`InstructionSet` answers decoded packets for a list of servos it shares with
:class:`sim.dynamixel.bus.EmulatedBus`, which owns the pty, the clock, the timing and the lock.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

from ...wire import dynamixel as tables
from . import protocol
from .servo import EmulatedServo

_PING, _READ, _OTHER = 0, 1, 2  # reply kinds, compared with Status_Return_Level
_CLEAR_KEY = bytes([0x01, 0x44, 0x58, 0x4C, 0x22])
_ID_ADDRESS = tables.X_SERIES_CONTROL_TABLE["ID"][0]
_LEVEL_ADDRESS = tables.X_SERIES_CONTROL_TABLE["Status_Return_Level"][0]
_HW_ERROR_ADDRESS = tables.X_SERIES_CONTROL_TABLE["Hardware_Error_Status"][0]


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


class InstructionSet:
    """The instruction handlers of one bus: a decoded packet in, the status packets out."""

    def __init__(self, servos: list[EmulatedServo]) -> None:
        self._servos = servos  # the bus's own list: servos added later are answered too
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

    def dispatch(self, packet: protocol.Packet | protocol.BadPacket) -> list[Reply]:
        if isinstance(packet, protocol.BadPacket):
            target = self.find(packet.servo_id)
            return self._status(target, tables.ERR_CRC, b"", _OTHER) if target else []
        if packet.is_status:
            return []
        group_handler = self._group_handlers.get(packet.instruction)
        if group_handler is not None:
            return group_handler(packet)
        if packet.servo_id == protocol.BROADCAST_ID:
            targets = sorted(self._servos, key=lambda s: s.id)
        else:
            found = self.find(packet.servo_id)
            targets = [found] if found else []
        handler = self._handlers.get(packet.instruction)
        if handler is None:
            if packet.servo_id == protocol.BROADCAST_ID or not targets:
                return []
            return self._status(targets[0], tables.ERR_INSTRUCTION, b"", _OTHER)
        return handler(packet, targets)

    def find(self, servo_id: int) -> EmulatedServo | None:
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
            s = self.find(servo_id)
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
            s = self.find(params[i])
            if s is not None:
                s.write_unanswered(address, params[i + 1 : i + chunk])
        return []

    def _bulk_read(self, packet: protocol.Packet) -> list[Reply]:
        params = packet.params
        if packet.servo_id != protocol.BROADCAST_ID or not params or len(params) % 5:
            return []
        out: list[Reply] = []
        for i in range(0, len(params), 5):
            s = self.find(params[i])
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
            s = self.find(params[i])
            if s is not None:
                s.write_unanswered(_word(params, i + 1), data)
            i += 5 + length
        return []


def _word(data: bytes, offset: int) -> int:
    return data[offset] | (data[offset + 1] << 8)
