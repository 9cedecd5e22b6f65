"""The streaming parser: recovery after garbage, truncation and bit flips; exact counters."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from palpate.sensor.parser import FrameParser
from palpate.wire.frame import MARKER, Frame, FrameLayout, encode

LAYOUT = FrameLayout(3)
SIZE = LAYOUT.size


def make(seq: int) -> Frame:
    return Frame(seq, 1000 * seq, seq - 5, 0, (1_530_000_000 + seq, 1_535_000_000, 1_540_000_000))


FRAMES = [make(i) for i in range(6)]
STREAM = [encode(f) for f in FRAMES]


def parse(data: bytes, chunk: int | None = None) -> tuple[list[Frame], FrameParser]:
    p = FrameParser(LAYOUT)
    if chunk is None:
        return p.feed(data), p
    out: list[Frame] = []
    for i in range(0, len(data), chunk):
        out += p.feed(data[i : i + chunk])
    return out, p


def test_clean_stream_any_chunking() -> None:
    data = b"".join(STREAM)
    for chunk in (None, 1, 2, 7, SIZE, SIZE + 1):
        frames, p = parse(data, chunk)
        assert frames == FRAMES
        c = p.counters
        assert (c.frames, c.bytes_discarded, c.sync_losses, c.bad_headers, c.crc_errors) == (
            6,
            0,
            0,
            0,
            0,
        )
        assert c.bytes_received == len(data)
        assert p.pending == 0


@pytest.mark.parametrize("bit", range(SIZE * 8))
def test_bit_flip_at_every_offset_loses_only_that_frame(bit: int) -> None:
    bad = bytearray(STREAM[2])
    bad[bit // 8] ^= 1 << (bit % 8)
    data = b"".join([*STREAM[:2], bytes(bad), *STREAM[3:]])
    frames, p = parse(data)
    assert frames == FRAMES[:2] + FRAMES[3:]
    c = p.counters
    offset = bit // 8
    expected = (1, 0, 0) if offset < 3 else (0, 1, 0) if offset < 6 else (0, 0, 1)
    assert (c.sync_losses, c.bad_headers, c.crc_errors) == expected
    assert (c.seq_gaps, c.frames_lost) == (1, 1)
    assert c.bytes_discarded == SIZE
    assert c.bytes_received == c.frames * SIZE + c.bytes_discarded + p.pending


@pytest.mark.parametrize("keep", range(1, SIZE))
def test_truncation_at_every_length_recovers_the_next_frame(keep: int) -> None:
    data = b"".join([*STREAM[:2], STREAM[2][:keep], *STREAM[3:]])
    frames, p = parse(data)
    assert frames == FRAMES[:2] + FRAMES[3:]
    c = p.counters
    expected = (1, 0, 0) if keep < 3 else (0, 1, 0) if keep < 6 else (0, 0, 1)
    assert (c.sync_losses, c.bad_headers, c.crc_errors) == expected
    assert c.frames_lost == 1
    assert c.bytes_discarded == keep


@pytest.mark.parametrize("offset", range(SIZE + 1))
def test_garbage_inserted_at_every_offset(offset: int) -> None:
    """Garbage shaped like a header prefix, put at every offset of frame 2 and between frames."""
    garbage = MARKER + b"\x07" + MARKER[:2]
    joined = b"".join(STREAM)
    at = 2 * SIZE + offset
    frames, p = parse(joined[:at] + garbage + joined[at:])
    if offset in (0, SIZE):  # between frames: nothing lost
        assert frames == FRAMES
    else:  # frame 2 is lost, except at offset 2 where the garbage's tail completes its sync
        assert [f for f in frames if f.seq != 2] == FRAMES[:2] + FRAMES[3:]
        assert all(f in FRAMES for f in frames)
    c = p.counters
    assert c.bytes_received == c.frames * SIZE + c.bytes_discarded + p.pending
    assert p.pending == 0


@given(st.binary(max_size=300), st.binary(max_size=300), st.integers(1, 64))
def test_random_garbage_never_raises_and_frames_after_it_survive(
    head: bytes, tail: bytes, chunk: int
) -> None:
    data = head + b"".join(STREAM) + tail
    frames, p = parse(data, chunk)
    assert frames == FRAMES
    c = p.counters
    assert c.bytes_received == c.frames * SIZE + c.bytes_discarded + p.pending


def test_impossible_length_is_rejected_without_waiting() -> None:
    bogus = MARKER + bytes([3, 0, 0xFF])  # a 255-byte payload: impossible for this layout
    frames, p = parse(b"".join(STREAM[:1]) + bogus)
    assert frames == FRAMES[:1]
    assert p.counters.bad_headers == 1
    assert p.pending <= 2  # nothing is held back waiting for 255 bytes


def test_sequence_gaps_wrap_and_reorder() -> None:
    seqs = [2**32 - 2, 2**32 - 1, 0, 3, 4, 2]
    frames, p = parse(b"".join(encode(make(0)._replace(seq=s)) for s in seqs))
    assert [f.seq for f in frames] == seqs
    c = p.counters
    assert (c.seq_gaps, c.frames_lost, c.out_of_order) == (1, 2, 1)


def test_partial_frame_waits_for_the_rest() -> None:
    p = FrameParser(LAYOUT)
    assert p.feed(STREAM[0][:25]) == []
    assert p.pending == 25
    assert p.feed(STREAM[0][25:]) == [FRAMES[0]]
    assert p.pending == 0
