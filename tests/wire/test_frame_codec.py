"""The frame codec byte by byte, its failure reasons, and property-based round trips."""

from __future__ import annotations

import zlib

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from palpate.wire.frame import (
    MARKER,
    Frame,
    FrameError,
    FrameLayout,
    Status,
    decode,
    encode,
    frame_from_si,
    parse_header,
)
from palpate.wire.frameblock import FrameBlock, crc32_rows, decode_block, encode_block

# A frame written out by hand from the table in docs/frame-protocol.md.
GOLDEN = Frame(seq=1, timestamp_us=2, encoder=-3, flags=4, peak_fm=(1_530_000_000, 2, 3))
GOLDEN_BYTES = bytes.fromhex(
    "a55a"
    "01"
    "03"
    "00"
    "1e"  # sync, version, n_peaks, options, length = 18 + 12
    "01000000"  # seq
    "0200000000000000"  # timestamp_us
    "fdffffff"  # encoder -3
    "0400"  # flags
    "80f2315b"
    "02000000"
    "03000000"  # peaks
)


def test_golden_frame_byte_by_byte() -> None:
    expected = GOLDEN_BYTES + zlib.crc32(GOLDEN_BYTES).to_bytes(4, "little")
    assert encode(GOLDEN) == expected
    assert decode(expected) == GOLDEN
    assert FrameLayout(3).size == len(expected) == 40


def test_crc_is_crc32_iso_hdlc() -> None:
    # The standard check value of CRC-32/ISO-HDLC, quoted in the protocol document.
    assert zlib.crc32(b"123456789") == 0xCBF43926


def test_optional_fields_follow_the_peaks() -> None:
    f = Frame(7, 8, 9, int(Status.FORCE_VALID), (10, 11), reference_fm=12, force_un=-13)
    data = encode(f)
    layout = FrameLayout(2, has_reference=True, has_force=True)
    assert data[:6] == layout.header == MARKER + bytes([2, 0x03, 18 + 8 + 8])
    assert data[24:32] == (10).to_bytes(4, "little") + (11).to_bytes(4, "little")
    assert data[32:36] == (12).to_bytes(4, "little")
    assert data[36:40] == (-13).to_bytes(4, "little", signed=True)
    assert decode(data, layout) == f


@pytest.mark.parametrize(
    ("mutate", "reason"),
    [
        (lambda b: b[:5], "short"),
        (lambda b: b[:20], "short"),
        (lambda b: b"\xa5\x5b" + b[2:], "sync"),
        (lambda b: b[:2] + b"\x02" + b[3:], "sync"),
        (lambda b: b[:3] + b"\x00" + b[4:], "header"),
        (lambda b: b[:3] + b"\x21" + b[4:], "header"),
        (lambda b: b[:4] + b"\x04" + b[5:], "header"),
        (lambda b: b[:5] + b"\xff" + b[6:], "header"),
        (lambda b: b[:-1] + bytes([b[-1] ^ 1]), "crc"),
    ],
)
def test_decode_names_the_failed_check(mutate: object, reason: str) -> None:
    assert callable(mutate)
    with pytest.raises(FrameError) as info:
        decode(mutate(encode(GOLDEN)))
    assert info.value.reason == reason
    assert isinstance(info.value, ValueError)


def test_decode_rejects_another_layout() -> None:
    with pytest.raises(FrameError, match="expected"):
        decode(encode(GOLDEN), FrameLayout(3, has_force=True))


def test_parse_header_accepts_every_valid_layout() -> None:
    for n in (1, 3, 32):
        for ref in (False, True):
            for force in (False, True):
                layout = FrameLayout(n, ref, force)
                assert parse_header(layout.header) == layout


@pytest.mark.parametrize(
    "frame",
    [
        GOLDEN._replace(seq=2**32),
        GOLDEN._replace(encoder=2**31),
        GOLDEN._replace(flags=0x10000),
        GOLDEN._replace(peak_fm=(-1, 0, 0)),
        GOLDEN._replace(force_un=2**31),
    ],
)
def test_encode_rejects_values_that_do_not_fit(frame: Frame) -> None:
    with pytest.raises(ValueError, match="outside"):
        encode(frame)


def test_layout_bounds() -> None:
    with pytest.raises(ValueError, match="n_peaks"):
        FrameLayout(0)
    with pytest.raises(ValueError, match="n_peaks"):
        FrameLayout(33)


def test_si_conversion_at_the_boundary() -> None:
    f = frame_from_si(5, 1.25, 10, [1550e-9, 1530.5e-9], reference=1540e-9, force=0.75)
    assert f.peak_fm == (1_550_000_000, 1_530_500_000)
    assert f.timestamp_us == 1_250_000
    assert f.force_un == 750_000
    np.testing.assert_allclose(f.wavelengths, [1550e-9, 1530.5e-9], rtol=1e-15)
    assert f.time == pytest.approx(1.25)
    assert f.force == pytest.approx(0.75)
    assert f.reference == pytest.approx(1540e-9)


u32 = st.integers(0, 2**32 - 1)
i32 = st.integers(-(2**31), 2**31 - 1)


@st.composite
def frames(draw: st.DrawFn) -> Frame:
    n = draw(st.integers(1, 32))
    return Frame(
        seq=draw(u32),
        timestamp_us=draw(st.integers(0, 2**64 - 1)),
        encoder=draw(i32),
        flags=draw(st.integers(0, 0xFFFF)),
        peak_fm=tuple(draw(st.lists(u32, min_size=n, max_size=n))),
        reference_fm=draw(st.none() | u32),
        force_un=draw(st.none() | i32),
    )


@given(frames())
def test_round_trip(frame: Frame) -> None:
    data = encode(frame)
    assert len(data) == frame.layout.size
    assert decode(data) == frame
    assert decode(data + b"trailing", frame.layout) == frame


@given(frames(), st.data())
def test_every_single_bit_flip_is_detected(frame: Frame, data: st.DataObject) -> None:
    raw = bytearray(encode(frame))
    bit = data.draw(st.integers(0, len(raw) * 8 - 1))
    raw[bit // 8] ^= 1 << (bit % 8)
    with pytest.raises(FrameError):
        decode(bytes(raw), frame.layout)


@given(st.lists(frames(), min_size=1, max_size=20), st.data())
def test_block_round_trip_matches_the_scalar_codec(items: list[Frame], data: st.DataObject) -> None:
    layout = items[0].layout
    same = [f for f in items if f.layout == layout]
    stream = b"".join(encode(f) for f in same)
    block, stats = decode_block(stream, layout)
    assert [block.frame(i) for i in range(len(block))] == same
    assert stats.bytes_skipped == 0
    assert encode_block(block) == stream
    # Garbage in front, between and behind is skipped.
    junk = data.draw(st.binary(max_size=50))
    block2, _ = decode_block(junk + stream + junk, layout)
    assert [block2.frame(i) for i in range(len(block2))] == same


@given(st.lists(st.binary(min_size=7, max_size=7), min_size=1, max_size=30))
def test_crc32_rows_equals_zlib(rows: list[bytes]) -> None:
    arr = np.frombuffer(b"".join(rows), dtype=np.uint8).reshape(len(rows), 7)
    assert crc32_rows(arr).tolist() == [zlib.crc32(r) for r in rows]


def test_decode_block_with_corruption_and_si_views() -> None:
    layout = FrameLayout(3, has_force=True)
    n = 50
    block = FrameBlock(
        seq=np.arange(n, dtype=np.uint32),
        timestamp_us=np.arange(n, dtype=np.uint64) * np.uint64(1000),
        encoder=np.arange(n, dtype=np.int32) - 25,
        flags=np.zeros(n, dtype=np.uint16),
        peak_fm=np.full((n, 3), 1_540_000_000, dtype=np.uint32),
        force_un=np.full(n, -2_000_000, dtype=np.int32),
    )
    raw = bytearray(encode_block(block))
    raw[10 * layout.size + 20] ^= 0x40  # corrupt frame 10
    out, stats = decode_block(bytes(raw), layout)
    assert out.seq.tolist() == [i for i in range(n) if i != 10]
    assert stats.rejected == 1
    assert stats.bytes_skipped == layout.size
    np.testing.assert_allclose(out.wavelengths, 1540e-9)
    assert out.force is not None
    np.testing.assert_allclose(out.force, -2.0)
    assert out.time[1] == pytest.approx(1e-3)


def test_decode_block_on_empty_and_short_input() -> None:
    out, stats = decode_block(b"", FrameLayout(3))
    assert len(out) == 0
    assert stats.bytes_skipped == 0
    out, _ = decode_block(encode(GOLDEN)[:-1], FrameLayout(3))
    assert len(out) == 0
