"""Conformance of the emulated bus: the unmodified dynamixel_sdk over a real pty, and raw packets.

Time is the VirtualClock's: nothing moves unless a test advances it, and no test sleeps.
"""

from __future__ import annotations

from collections.abc import Iterator

import dynamixel_sdk as sdk
import pytest

from palpate.sim.clock import VirtualClock
from palpate.sim.dynamixel import protocol as p
from palpate.sim.dynamixel.bus import EmulatedBus
from palpate.sim.dynamixel.servo import EmulatedServo
from palpate.wire import dynamixel as tables

PH = sdk.PacketHandler(2.0)


@pytest.fixture
def clock() -> VirtualClock:
    return VirtualClock()


@pytest.fixture
def bus(clock: VirtualClock) -> Iterator[EmulatedBus]:
    servos = [EmulatedServo(3, "XL430-W250"), EmulatedServo(1), EmulatedServo(2)]
    with EmulatedBus(servos, clock=clock) as b:
        yield b


class PatientPort(sdk.PortHandler):  # type: ignore[misc]
    """The SDK's port with a 3 s reply timeout instead of its 34 ms, which races the emulator's
    thread on a busy machine (1 s was missed once, seven processes on two cores); a reply that
    comes is read at once, so only the two tests that expect no reply wait the timeout out."""

    def setPacketTimeout(self, packet_length: int) -> None:
        self.packet_start_time = self.getCurrentTime()
        self.packet_timeout = self.tx_time_per_byte * packet_length + 3000.0


@pytest.fixture
def port(bus: EmulatedBus) -> Iterator[sdk.PortHandler]:
    handler = PatientPort(bus.port)
    assert handler.openPort()
    assert handler.setBaudRate(1_000_000)
    yield handler
    handler.closePort()


def _statuses(raw: bytes) -> list[p.Packet]:
    packets = p.PacketReader().feed(raw)
    assert all(isinstance(x, p.Packet) for x in packets)
    return [x for x in packets if isinstance(x, p.Packet)]


# --- over the pty with the SDK -----------------------------------------------------------------
def test_sdk_pings_and_identifies_models(port: sdk.PortHandler) -> None:
    assert PH.ping(port, 1) == (1020, sdk.COMM_SUCCESS, 0)
    assert PH.ping(port, 3) == (1060, sdk.COMM_SUCCESS, 0)
    assert PH.read2ByteTxRx(port, 3, 0) == (1060, sdk.COMM_SUCCESS, 0)
    _, result, _ = PH.ping(port, 42)
    assert result == sdk.COMM_RX_TIMEOUT


def test_sdk_broadcast_ping_finds_every_servo(port: sdk.PortHandler) -> None:
    found, result = PH.broadcastPing(port)
    assert result == sdk.COMM_SUCCESS
    assert found == {1: [1020, 46], 2: [1020, 46], 3: [1060, 46]}


def test_sdk_write_read_signed_and_stuffed_values(bus: EmulatedBus, port: sdk.PortHandler) -> None:
    assert PH.write1ByteTxRx(port, 1, 11, 4) == (sdk.COMM_SUCCESS, 0)
    goal = -131073  # little-endian FF FF FD FF: stuffed both ways
    assert PH.write4ByteTxRx(port, 1, 116, goal & 0xFFFFFFFF) == (sdk.COMM_SUCCESS, 0)
    value, result, error = PH.read4ByteTxRx(port, 1, 116)
    assert (result, error) == (sdk.COMM_SUCCESS, 0)
    assert value == goal & 0xFFFFFFFF  # the SDK hands back raw unsigned values
    assert bus.servo(1).item("Goal_Position") == goal


def test_sdk_sees_access_errors(port: sdk.PortHandler) -> None:
    assert PH.write1ByteTxRx(port, 2, 64, 1) == (sdk.COMM_SUCCESS, 0)
    assert PH.write1ByteTxRx(port, 2, 11, 4) == (sdk.COMM_SUCCESS, tables.ERR_ACCESS)
    assert PH.write4ByteTxRx(port, 2, 132, 0) == (sdk.COMM_SUCCESS, tables.ERR_ACCESS)


def test_motion_follows_the_virtual_clock(
    bus: EmulatedBus, port: sdk.PortHandler, clock: VirtualClock
) -> None:
    PH.write1ByteTxRx(port, 2, 11, 4)
    PH.write1ByteTxRx(port, 2, 64, 1)
    PH.write4ByteTxRx(port, 2, 116, 20_000)
    assert PH.read4ByteTxRx(port, 2, 132)[0] == 0
    clock.advance(10.0)
    assert PH.read4ByteTxRx(port, 2, 132)[0] == 20_000
    assert bus.servo(2).position_ticks == 20_000


def test_sdk_sync_write_and_sync_read(
    bus: EmulatedBus, port: sdk.PortHandler, clock: VirtualClock
) -> None:
    for i in (1, 2, 3):
        PH.write1ByteTxRx(port, i, 64, 1)
    writer = sdk.GroupSyncWrite(port, PH, 116, 4)
    for i in (1, 2, 3):
        assert writer.addParam(i, list((1000 * i).to_bytes(4, "little")))
    assert writer.txPacket() == sdk.COMM_SUCCESS
    assert PH.ping(port, 1)[1] == sdk.COMM_SUCCESS  # a reply: the sync write was handled
    clock.advance(5.0)
    reader = sdk.GroupSyncRead(port, PH, 132, 4)
    for i in (3, 1, 2):
        reader.addParam(i)
    assert reader.txRxPacket() == sdk.COMM_SUCCESS
    assert [reader.getData(i, 132, 4) for i in (1, 2, 3)] == [1000, 2000, 3000]


def test_sdk_bulk_write_and_bulk_read(bus: EmulatedBus, port: sdk.PortHandler) -> None:
    writer = sdk.GroupBulkWrite(port, PH)
    assert writer.addParam(1, 65, 1, [1])
    assert writer.addParam(3, 112, 4, list((77).to_bytes(4, "little")))
    assert writer.txPacket() == sdk.COMM_SUCCESS
    reader = sdk.GroupBulkRead(port, PH)
    assert reader.addParam(1, 65, 1)
    assert reader.addParam(3, 112, 4)
    assert reader.addParam(2, 0, 2)
    assert reader.txRxPacket() == sdk.COMM_SUCCESS
    assert reader.getData(1, 65, 1) == 1
    assert reader.getData(3, 112, 4) == 77
    assert reader.getData(2, 0, 2) == 1020


def test_sdk_reg_write_and_action(bus: EmulatedBus, port: sdk.PortHandler) -> None:
    assert PH.regWriteTxRx(port, 2, 65, 1, [1]) == (sdk.COMM_SUCCESS, 0)
    assert PH.read1ByteTxRx(port, 2, 69)[0] == 1
    assert bus.servo(2).item("LED") == 0
    assert PH.action(port, 2) == sdk.COMM_SUCCESS
    assert PH.read1ByteTxRx(port, 2, 65) == (1, sdk.COMM_SUCCESS, 0)
    assert PH.read1ByteTxRx(port, 2, 69)[0] == 0


def test_sdk_reboot_clears_a_hardware_error(bus: EmulatedBus, port: sdk.PortHandler) -> None:
    bus.servo(1).raise_hardware_error(tables.HW_OVERLOAD)
    value, result, error = PH.read1ByteTxRx(port, 1, 70)
    assert (value, result) == (tables.HW_OVERLOAD, sdk.COMM_SUCCESS)
    assert error == tables.ALERT_BIT
    assert PH.write1ByteTxRx(port, 1, 64, 1) == (
        sdk.COMM_SUCCESS,
        tables.ALERT_BIT | tables.ERR_RESULT_FAIL,
    )
    result, error = PH.reboot(port, 1)
    assert result == sdk.COMM_SUCCESS
    assert PH.read1ByteTxRx(port, 1, 70) == (0, sdk.COMM_SUCCESS, 0)


def test_sdk_factory_reset_and_clear_multi_turn(
    bus: EmulatedBus, port: sdk.PortHandler, clock: VirtualClock
) -> None:
    PH.write1ByteTxRx(port, 2, 11, 4)
    PH.write1ByteTxRx(port, 2, 64, 1)
    PH.write4ByteTxRx(port, 2, 116, 2 * 4096 + 5)
    clock.advance(10.0)
    assert PH.clearMultiTurn(port, 2) == (sdk.COMM_SUCCESS, 0)
    assert PH.read4ByteTxRx(port, 2, 132)[0] == 5
    PH.write1ByteTxRx(port, 2, 64, 0)
    assert PH.factoryReset(port, 2, 0x01) == (sdk.COMM_SUCCESS, 0)
    assert PH.read1ByteTxRx(port, 2, 11) == (3, sdk.COMM_SUCCESS, 0)


def test_injected_reply_faults_reach_the_sdk(bus: EmulatedBus, port: sdk.PortHandler) -> None:
    bus.servo(1).drop_replies(1)
    assert PH.ping(port, 1)[1] == sdk.COMM_RX_TIMEOUT
    bus.servo(1).corrupt_replies(1)
    assert PH.ping(port, 1)[1] == sdk.COMM_RX_CORRUPT
    assert PH.ping(port, 1) == (1020, sdk.COMM_SUCCESS, 0)


# --- raw packets in process (the same code path the pty thread runs) ----------------------------
def test_broadcast_ping_answers_in_id_order() -> None:
    bus = EmulatedBus([EmulatedServo(7), EmulatedServo(2, "XL430-W250"), EmulatedServo(4)])
    replies = _statuses(bus.handle(p.encode(p.BROADCAST_ID, p.INST_PING)))
    assert [r.servo_id for r in replies] == [2, 4, 7]
    assert replies[0].params[:2] == p.u16(1060)


def test_broadcast_write_applies_to_all_without_reply() -> None:
    bus = EmulatedBus([EmulatedServo(1), EmulatedServo(2)])
    assert bus.handle(p.encode(p.BROADCAST_ID, p.INST_WRITE, p.u16(65) + b"\x01")) == b""
    assert [s.item("LED") for s in bus.servos] == [1, 1]
    assert bus.handle(p.encode(p.BROADCAST_ID, p.INST_READ, p.u16(0) + p.u16(2))) == b""


def test_status_return_level() -> None:
    bus = EmulatedBus([EmulatedServo(1)])
    read = p.encode(1, p.INST_READ, p.u16(0) + p.u16(2))
    write = p.encode(1, p.INST_WRITE, p.u16(65) + b"\x01")
    ping = p.encode(1, p.INST_PING)
    bus.handle(p.encode(1, p.INST_WRITE, p.u16(68) + b"\x01"))
    assert bus.handle(write) == b""
    assert len(_statuses(bus.handle(read))) == 1
    bus.handle(p.encode(1, p.INST_WRITE, p.u16(68) + b"\x00"))
    assert bus.handle(read) == b""
    assert len(_statuses(bus.handle(ping))) == 1


def test_crc_error_instruction_error_and_data_length_error() -> None:
    bus = EmulatedBus([EmulatedServo(1)])
    raw = bytearray(p.encode(1, p.INST_PING))
    raw[-2] ^= 0xFF
    (status,) = _statuses(bus.handle(bytes(raw)))
    assert status.error == tables.ERR_CRC
    (status,) = _statuses(bus.handle(p.encode(1, 0x42)))
    assert status.error == tables.ERR_INSTRUCTION
    (status,) = _statuses(bus.handle(p.encode(1, p.INST_READ, b"\x00")))
    assert status.error == tables.ERR_DATA_LENGTH
    assert bus.handle(p.encode(9, p.INST_PING)) == b""  # nobody at ID 9


def test_action_and_broadcast_reboot_are_silent() -> None:
    bus = EmulatedBus([EmulatedServo(1), EmulatedServo(2)])
    bus.handle(p.encode(1, p.INST_REG_WRITE, p.u16(65) + b"\x01"))
    assert bus.handle(p.encode(p.BROADCAST_ID, p.INST_ACTION)) == b""
    assert bus.servo(1).item("LED") == 1
    assert bus.handle(p.encode(p.BROADCAST_ID, p.INST_REBOOT)) == b""
    assert bus.servo(1).item("LED") == 0


def test_sync_read_skips_absent_servos_and_keeps_order() -> None:
    bus = EmulatedBus([EmulatedServo(1), EmulatedServo(2)])
    replies = _statuses(
        bus.handle(
            p.encode(p.BROADCAST_ID, p.INST_SYNC_READ, p.u16(0) + p.u16(2) + bytes([2, 9, 1]))
        )
    )
    assert [r.servo_id for r in replies] == [2, 1]


def test_bus_rejects_duplicate_ids_and_finds_servos() -> None:
    bus = EmulatedBus([EmulatedServo(1)])
    with pytest.raises(ValueError, match="already"):
        bus.add(EmulatedServo(1))
    with pytest.raises(KeyError):
        bus.servo(5)


def test_real_time_mode_advances_on_wall_time() -> None:
    wall = [100.0]
    bus = EmulatedBus([EmulatedServo(1)], wall_time=lambda: wall[0])
    bus.handle(p.encode(1, p.INST_WRITE, p.u16(64) + b"\x01"))
    bus.handle(p.encode(1, p.INST_WRITE, p.u16(116) + p.u32(100)))
    assert bus.servo(1).position_ticks == 0
    wall[0] += 1.0
    bus.handle(b"")  # every packet (even none) first brings the servos up to wall time
    assert bus.servo(1).position_ticks == 100
