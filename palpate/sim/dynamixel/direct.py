"""The register-level path to the emulated servos: the driver's SDK calls without the packets.

``robot.dynamixel.DynamixelBus`` talks to the bus through two SDK objects: a port and a
``PacketHandler`` (``ping``, ``readTxRx``, ``writeTxRx``, ``write1ByteTxRx``, ``reboot``,
``syncReadTx`` / ``readRx``, ``syncWriteTxOnly``, ``getTxRxResult``). :class:`DirectPacketHandler`
answers those same calls with the same return values (data, COMM_* result, status error) from an
:class:`sim.dynamixel.bus.EmulatedBus`, handing it the decoded request
(:meth:`EmulatedBus.exchange`): no packet is built, stuffed, CRC'd, split or parsed on either
side. The bus executes the request with the same handlers as on the wire (registers, units,
access rules, clamps, Status Return Level, the Alert bit, hardware errors), so the driver above
it makes the same decisions it makes over the pty.

What a reply fault does here is what the SDK reports for it on the wire: a dropped reply is a
``COMM_RX_TIMEOUT`` (at once: there is no wire to wait on), a corrupted one ``COMM_RX_CORRUPT``.
Faults that act on the bytes themselves (``sim.dynamixel.faults.FaultyBus``: random loss, flipped
bytes, a reply filter) need the byte path; ``palpate.simulation.trial`` keeps the SDK on the
in-process port when a fault hook is given.

Why: on a bench trial the SDK's packet code and the emulator's parser were about a third of the
loop's CPU (cProfile of ``palpate sim --campaign bench``), for bytes no one looks at.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Sequence

import dynamixel_sdk as sdk

from . import protocol
from .bus import EmulatedBus
from .instructions import Reply

_SDK = sdk.PacketHandler(2.0)  # only for getTxRxResult / getRxPacketError: the same messages


class DirectPort:
    """Stands where the SDK's ``PortHandler`` stands for the driver: open/close, a name, the
    ``is_using`` flag the driver resets, and the replies of the last request not yet read."""

    def __init__(self, bus: EmulatedBus, name: str = "direct://dynamixel") -> None:
        self.bus = bus
        self.port_name = name
        self.baudrate = 1_000_000
        self.is_open = False
        self.is_using = False
        self.pending: deque[Reply] = deque()

    def openPort(self) -> bool:
        self.is_open = True
        return True

    def closePort(self) -> None:
        self.is_open = False

    def setBaudRate(self, baudrate: int) -> bool:
        self.baudrate = baudrate
        return True

    def getPortName(self) -> str:
        return self.port_name

    def send(self, servo_id: int, instruction: int, params: bytes) -> list[Reply]:
        """One request: what a new transmission does to the line (earlier replies are cleared),
        then the servos' answers, also kept in :attr:`pending` for ``readRx``."""
        self.pending.clear()
        replies = self.bus.exchange(protocol.Packet(servo_id, instruction, params))
        self.pending.extend(replies)
        return replies


class DirectPacketHandler:
    """The subset of ``dynamixel_sdk.PacketHandler(2.0)`` the driver calls, on a DirectPort."""

    def getProtocolVersion(self) -> float:
        return 2.0

    def getTxRxResult(self, result: int) -> str:
        return str(_SDK.getTxRxResult(result))

    def getRxPacketError(self, error: int) -> str:
        return str(_SDK.getRxPacketError(error))

    # --- request and reply (the SDK's txRxPacket) ----------------------------------------------
    def _tx_rx(
        self, port: DirectPort, servo_id: int, instruction: int, params: bytes
    ) -> tuple[Reply | None, int, int]:
        """(reply, result, error) as ``txRxPacket``: a broadcast waits for nothing; otherwise
        the first reply from ``servo_id``; a corrupt reply read first is COMM_RX_CORRUPT."""
        port.send(servo_id, instruction, params)
        if servo_id == protocol.BROADCAST_ID or instruction == protocol.INST_ACTION:
            return None, sdk.COMM_SUCCESS, 0
        return self._next_reply(port, servo_id)

    @staticmethod
    def _next_reply(port: DirectPort, servo_id: int) -> tuple[Reply | None, int, int]:
        """The SDK's read loop: skip other servos' replies until ``servo_id``'s (readRx)."""
        pending = port.pending
        while pending:
            reply = pending.popleft()
            if reply.corrupt:
                return None, sdk.COMM_RX_CORRUPT, 0
            if reply.servo_id == servo_id:
                return reply, sdk.COMM_SUCCESS, reply.error
        return None, sdk.COMM_RX_TIMEOUT, 0

    # --- the calls the driver makes -------------------------------------------------------------
    def ping(self, port: DirectPort, dxl_id: int) -> tuple[int, int, int]:
        if dxl_id >= protocol.BROADCAST_ID:
            return 0, sdk.COMM_NOT_AVAILABLE, 0
        reply, result, error = self._tx_rx(port, dxl_id, protocol.INST_PING, b"")
        if reply is None:
            return 0, result, error
        params = reply.params + b"\x00\x00"  # the SDK reads two bytes whatever came
        return params[0] | (params[1] << 8), result, error

    def readTxRx(
        self, port: DirectPort, dxl_id: int, address: int, length: int
    ) -> tuple[list[int], int, int]:
        if dxl_id >= protocol.BROADCAST_ID:
            return [], sdk.COMM_NOT_AVAILABLE, 0
        request = protocol.u16(address) + protocol.u16(length)
        reply, result, error = self._tx_rx(port, dxl_id, protocol.INST_READ, request)
        return ([] if reply is None else list(reply.params[:length])), result, error

    def writeTxRx(
        self, port: DirectPort, dxl_id: int, address: int, length: int, data: Sequence[int]
    ) -> tuple[int, int]:
        request = protocol.u16(address) + bytes(data[:length])
        _, result, error = self._tx_rx(port, dxl_id, protocol.INST_WRITE, request)
        return result, error

    def write1ByteTxRx(
        self, port: DirectPort, dxl_id: int, address: int, data: int
    ) -> tuple[int, int]:
        return self.writeTxRx(port, dxl_id, address, 1, [data])

    def reboot(self, port: DirectPort, dxl_id: int) -> tuple[int, int]:
        _, result, error = self._tx_rx(port, dxl_id, protocol.INST_REBOOT, b"")
        return result, error

    def syncReadTx(
        self,
        port: DirectPort,
        start_address: int,
        data_length: int,
        param: Sequence[int],
        param_length: int,
        fast_option: bool = False,
    ) -> int:
        inst = protocol.INST_FAST_SYNC_READ if fast_option else protocol.INST_SYNC_READ
        port.send(
            protocol.BROADCAST_ID, inst, _group(start_address, data_length, param, param_length)
        )
        return int(sdk.COMM_SUCCESS)

    def readRx(self, port: DirectPort, dxl_id: int, length: int) -> tuple[list[int], int, int]:
        reply, result, error = self._next_reply(port, dxl_id)
        return ([] if reply is None else list(reply.params[:length])), result, error

    def syncWriteTxOnly(
        self,
        port: DirectPort,
        start_address: int,
        data_length: int,
        param: Sequence[int],
        param_length: int,
    ) -> int:
        request = _group(start_address, data_length, param, param_length)
        port.send(protocol.BROADCAST_ID, protocol.INST_SYNC_WRITE, request)
        return int(sdk.COMM_SUCCESS)


def _group(address: int, length: int, param: Sequence[int], param_length: int) -> bytes:
    """A sync instruction's parameters: start address, data length, then the per-servo part."""
    return protocol.u16(address) + protocol.u16(length) + bytes(param[:param_length])


def direct_transport(bus: EmulatedBus) -> tuple[DirectPort, DirectPacketHandler]:
    """The port and packet handler to give ``DynamixelBus`` for the register-level path."""
    return DirectPort(bus), DirectPacketHandler()


__all__ = ["DirectPacketHandler", "DirectPort", "direct_transport"]
