"""Board frames from bytes: the resynchronising parser and the reader's counters.

:class:`FrameParser` is pure (bytes in, frames out) and never raises on bad bytes; it counts what
it rejects in :class:`ReaderCounters` (shared with :class:`sensor.reader.FrameReader`, which owns
the port). Rejection accounting (each rejected candidate increments exactly one counter):

- ``sync_losses``: a frame was expected right after a valid one but the bytes there are not the
  sync word and version (inserted garbage, a corrupted sync byte, a truncated frame);
- ``bad_headers``: sync and version found, but ``n_peaks``/``options``/``length`` are not the
  configured layout (an impossible length is rejected at once, never waited for);
- ``crc_errors``: the header is right but the CRC is not.

After a rejection the parser hunts for the next sync word one byte further on, so a valid frame
that begins inside rejected bytes is still found. While hunting, bytes that hold no sync word
are only counted in ``bytes_discarded``.
"""

from __future__ import annotations

import zlib
from dataclasses import asdict, dataclass

from ..config.schema import BoardConfig, SensorConfig
from ..wire.frame import CRC_SIZE, HEADER_SIZE, MARKER, Frame, FrameLayout, layout_of, unpack

SEQ_MOD = 2**32


@dataclass
class ReaderCounters:
    """Running totals; ``bytes_received == frames * size + bytes_discarded + pending``."""

    bytes_received: int = 0
    frames: int = 0
    bytes_discarded: int = 0
    sync_losses: int = 0
    bad_headers: int = 0
    crc_errors: int = 0
    seq_gaps: int = 0
    frames_lost: int = 0
    out_of_order: int = 0
    stale_events: int = 0
    port_errors: int = 0  # reads that failed (EOF, EIO, no data behind readiness): port lost
    reopens: int = 0  # times a lost port was opened again

    def as_dict(self) -> dict[str, int]:
        return asdict(self)


class FrameParser:
    """Incremental parser for one layout: ``feed(bytes) -> frames``; never raises on content."""

    def __init__(self, layout: FrameLayout, counters: ReaderCounters | None = None) -> None:
        self.layout = layout
        self.counters = counters if counters is not None else ReaderCounters()
        self._buf = bytearray()
        self._synced = False
        self._last_seq: int | None = None

    @property
    def pending(self) -> int:
        """Bytes held back until more arrive (a partial frame or a possible sync prefix)."""
        return len(self._buf)

    def feed(self, data: bytes | bytearray) -> list[Frame]:
        """Parse ``data`` appended to what is pending; return the valid frames, oldest first."""
        c = self.counters
        c.bytes_received += len(data)
        buf = self._buf
        buf += data
        layout = self.layout
        header, size, unpack_from = layout.header, layout.size, layout.struct.unpack_from
        body = size - CRC_SIZE
        n = len(buf)
        i = 0
        frames: list[Frame] = []
        synced = self._synced
        with memoryview(buf) as mv:
            while True:
                if not synced:
                    j = buf.find(MARKER, i)
                    if j < 0:
                        keep = max(i, n - (len(MARKER) - 1))
                        c.bytes_discarded += keep - i
                        i = keep
                        break
                    c.bytes_discarded += j - i
                    i = j
                    synced = True
                if n - i < size or buf[i : i + HEADER_SIZE] != header:
                    # Decide early on what is already visible; wait only for a plausible frame.
                    if not self._count_rejection(buf, i, n):
                        break
                    synced = False
                    i += 1
                    c.bytes_discarded += 1
                    continue
                values = unpack_from(buf, i)
                if zlib.crc32(mv[i : i + body]) != values[-1]:
                    c.crc_errors += 1
                    synced = False
                    i += 1
                    c.bytes_discarded += 1
                    continue
                frame = unpack(layout, values)
                self._track_seq(frame.seq)
                frames.append(frame)
                i += size
        del buf[:i]
        self._synced = synced
        c.frames += len(frames)
        return frames

    def _count_rejection(self, buf: bytearray, i: int, n: int) -> bool:
        """Count why the bytes at ``i`` are not a frame header (a sync loss or a bad header);
        False when too few bytes are there to tell (a partial frame: wait for more)."""
        if n - i >= len(MARKER) and buf[i : i + len(MARKER)] != MARKER:
            self.counters.sync_losses += 1
        elif n - i >= HEADER_SIZE and buf[i : i + HEADER_SIZE] != self.layout.header:
            self.counters.bad_headers += 1
        else:
            return False
        return True

    def accept(self, frames: list[Frame]) -> list[Frame]:
        """Frames that arrived decoded: counted and sequence-checked as if parsed from bytes."""
        c = self.counters
        c.bytes_received += len(frames) * self.layout.size
        for frame in frames:
            self._track_seq(frame.seq)
        c.frames += len(frames)
        return frames

    def _track_seq(self, seq: int) -> None:
        last = self._last_seq
        self._last_seq = seq
        if last is None:
            return
        gap = (seq - last - 1) % SEQ_MOD
        if gap == 0:
            return
        if gap < SEQ_MOD // 2:
            self.counters.seq_gaps += 1
            self.counters.frames_lost += gap
        else:
            self.counters.out_of_order += 1


def layout_from_config(sensor: SensorConfig, board: BoardConfig) -> FrameLayout:
    """The stream's layout: one peak per used grating, in ``sensor.used_gratings`` order."""
    return layout_of(
        len(sensor.used_gratings),
        board.has_reference,
        board.has_force,
        sensor.tip_grating is not None,
    )
