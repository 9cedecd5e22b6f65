"""Protocol 2.0 framing byte by byte, and against the SDK's own encoder/decoder."""

from __future__ import annotations

import dynamixel_sdk as sdk
import pytest
from hypothesis import given
from hypothesis import strategies as st

from palpate.sim.dynamixel import protocol as p

# bytes biased toward the header and stuffing bytes
wire_bytes = st.lists(st.sampled_from([0xFF, 0xFD, 0x00, 0x55, 0x12]) | st.integers(0, 255)).map(
    bytes
)


class _CapturePort:
    """Just enough of a PortHandler for the SDK to hand us the bytes it would send."""

    def __init__(self) -> None:
        self.is_using = False
        self.sent = b""

    def clearPort(self) -> None:
        pass

    def writePort(self, packet: list[int]) -> int:
        self.sent = bytes(packet)
        return len(packet)


def test_ping_packet_matches_the_e_manual_example() -> None:
    assert p.encode(1, p.INST_PING) == bytes.fromhex("FFFFFD0001030001194E")


def test_status_packet_of_a_ping_reply_decodes() -> None:
    raw = p.encode_status(1, 0, p.u16(1020) + bytes([46]))
    packet = p.decode(raw)
    assert packet.is_status
    assert packet.params == bytes([0xFC, 0x03, 46])
    assert packet.error == 0


@given(st.binary(max_size=64))
def test_crc_matches_the_sdk(data: bytes) -> None:
    ph = sdk.PacketHandler(2.0)
    assert p.crc16(data) == ph.updateCRC(0, list(data), len(data))


@given(wire_bytes)
def test_unstuff_inverts_stuff(body: bytes) -> None:
    stuffed = p.stuff(body)
    assert p.unstuff(stuffed) == body
    # no header can appear inside a stuffed body followed by anything but FD
    for i in range(len(stuffed) - 3):
        if stuffed[i : i + 3] == b"\xff\xff\xfd":
            assert stuffed[i + 3] == 0xFD


@given(st.integers(0, 252), wire_bytes.filter(lambda b: len(b) <= 200))
def test_write_packet_is_byte_identical_to_the_sdk(servo_id: int, data: bytes) -> None:
    port = _CapturePort()
    ph = sdk.PacketHandler(2.0)
    payload = list(data)
    ph.writeTxOnly(port, servo_id, 0x74, len(payload), payload)
    ours = p.encode(servo_id, p.INST_WRITE, bytes([0x74, 0x00]) + data)
    assert ours == port.sent
    decoded = p.decode(port.sent)
    assert decoded.params == bytes([0x74, 0x00]) + data


@given(wire_bytes.filter(lambda b: len(b) <= 200))
def test_sdk_unstuffs_our_status_packets(data: bytes) -> None:
    raw = list(p.encode_status(7, 0, data))
    ph = sdk.PacketHandler(2.0)
    out = ph.removeStuffing(raw)
    length = out[5] | (out[6] << 8)
    assert bytes(out[9 : 9 + length - 4]) == data


def test_reader_splits_a_stream_with_garbage_and_partial_feeds() -> None:
    a = p.encode(1, p.INST_PING)
    b = p.encode(2, p.INST_READ, p.u16(132) + p.u16(4))
    stream = b"\x00\x12\xff" + a + b"\xfd" + b
    reader = p.PacketReader()
    got: list[p.Packet | p.BadPacket] = []
    for i in range(0, len(stream), 3):
        got += reader.feed(stream[i : i + 3])
    assert got == [p.decode(a), p.decode(b)]


def test_reader_reports_a_bad_crc() -> None:
    raw = bytearray(p.encode(3, p.INST_READ, p.u16(132) + p.u16(4)))
    raw[-1] ^= 0x01
    (bad,) = p.PacketReader().feed(bytes(raw))
    assert bad == p.BadPacket(3, p.INST_READ)


def test_decode_rejects_malformed_packets() -> None:
    good = p.encode(1, p.INST_PING)
    with pytest.raises(p.ProtocolError):
        p.decode(good[:-1])
    with pytest.raises(p.ProtocolError):
        p.decode(b"\x00" + good[1:])
    with pytest.raises(ValueError, match="servo id"):
        p.encode(300, p.INST_PING)


_packets = st.builds(
    p.encode,
    st.integers(0, 0xFE),
    st.sampled_from([p.INST_PING, p.INST_READ, p.INST_SYNC_READ, p.INST_SYNC_WRITE, p.INST_STATUS]),
    wire_bytes.filter(lambda b: len(b) <= 20),
)


@given(st.lists(_packets | wire_bytes, max_size=4))
def test_a_whole_feed_and_a_byte_wise_feed_agree(chunks: list[bytes]) -> None:
    # the reader's shortcut for one whole packet must give what the stream splitter gives
    data = b"".join(chunks)
    reader = p.PacketReader()
    byte_wise: list[p.Packet | p.BadPacket] = []
    for i in range(len(data)):
        byte_wise += reader.feed(data[i : i + 1])
    assert p.PacketReader().feed(data) == byte_wise


def test_a_corrupt_copy_of_a_remembered_packet_is_still_rejected() -> None:
    good = p.encode(p.BROADCAST_ID, p.INST_SYNC_READ, p.u16(122) + p.u16(14) + bytes([1, 2, 3]))
    reader = p.PacketReader()
    assert reader.feed(good) == reader.feed(good) == [p.decode(good)]
    bad = bytearray(good)
    bad[-1] ^= 0xFF
    assert reader.feed(bytes(bad)) == [p.BadPacket(p.BROADCAST_ID, p.INST_SYNC_READ)]
    with pytest.raises(p.ProtocolError):
        p.decode_cached(bytes(bad))


def test_status_encoding_takes_any_bytes_like_params_and_masks_the_error() -> None:
    expected = p.encode(1, p.INST_STATUS, b"\x80\x01\x02")
    assert p.encode_status(1, 0x180, bytearray(b"\x01\x02")) == expected
    assert p.encode_status(1, 0x80, b"\x01\x02") == expected
