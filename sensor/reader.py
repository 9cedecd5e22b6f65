"""Frames from the acquisition board over pyserial: resynchronising parser, counters, staleness.

:class:`FrameParser` is pure (bytes in, frames out) and never raises on bad bytes; it counts what
it rejects. :class:`FrameReader` owns a serial transport (a device path, a pty, a pyserial URL
such as ``loop://``, or an already open serial object) and adds sequence-gap and stale-stream
detection on an injected :class:`~sensor.clock.Clock`.

Rejection accounting (each rejected candidate increments exactly one counter):

- ``sync_losses``: a frame was expected right after a valid one but the bytes there are not the
  sync word and version (inserted garbage, a corrupted sync byte, a truncated frame);
- ``bad_headers``: sync and version found, but ``n_peaks``/``options``/``length`` are not the
  configured layout (an impossible length is rejected at once, never waited for);
- ``crc_errors``: the header is right but the CRC is not.

After a rejection the parser hunts for the next sync word one byte further on, so a valid frame
that begins inside rejected bytes is still found. While hunting, bytes that hold no sync word
are only counted in ``bytes_discarded``.

A port that fails under the reader (end of file, ``EIO``, pyserial's "device reports readiness
to read but returned no data": a board unplugged, a pty whose master closed) is a transient, not
an error: the reader counts it (``port_errors``), closes the port and opens it again with a
back-off on its clock (``reopens`` counts the successes), and meanwhile returns no frames. The
stream then goes stale, and what to do about a stale stream is the caller's decision (the trial's
FBG-lost guard). Only opening the port in the first place raises :class:`SensorPortError`.
"""

from __future__ import annotations

import contextlib
import threading
import time
import zlib
from dataclasses import asdict, dataclass
from types import TracebackType
from typing import Protocol

import serial

from config.schema import BoardConfig, SensorConfig
from sensor.clock import Clock, SystemClock
from sensor.ports import OPEN_ERRORS, PORT_ERRORS, Backoff, open_failure
from wire.frame import CRC_SIZE, HEADER_SIZE, MARKER, Frame, FrameLayout, layout_of, unpack

SEQ_MOD = 2**32
REOPEN_BACKOFF_S = (0.01, 1.0)  # first and longest wait between attempts to reopen a lost port


class SensorPortError(OSError):
    """The board's port cannot be opened or stopped working; the message names the port."""


class SerialLike(Protocol):
    """What the reader needs from a transport (``serial.Serial`` and pyserial URLs satisfy it)."""

    @property
    def in_waiting(self) -> int: ...

    def read(self, size: int = 1) -> bytes: ...

    def close(self) -> None: ...


class FrameTransport(SerialLike, Protocol):
    """A transport that hands over decoded frames (the simulator's in-process fast path,
    ``sim.inprocess.FramePipe``): the reader takes them instead of parsing bytes."""

    def take_frames(self) -> list[Frame]: ...


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
    return layout_of(len(sensor.used_gratings), board.has_reference, board.has_force)


class FrameReader:
    """Read frames from the board's serial stream; a context manager that closes its port.

    ``port`` is a device path, a pty path, a pyserial URL (``loop://``), or an open serial object
    (then the caller keeps ownership of its settings; the reader still closes it).
    ``clock`` stamps arrivals for stale detection and times the reopening back-off
    (:class:`SystemClock` by default; pass the simulator's virtual clock in simulation).
    ``read_timeout_s`` bounds one blocking read on the real transport.
    """

    def __init__(
        self,
        port: str | SerialLike,
        layout: FrameLayout,
        *,
        baudrate: int = 921600,
        clock: Clock | None = None,
        stale_timeout_s: float = 0.1,
        read_timeout_s: float = 0.05,
    ) -> None:
        if not stale_timeout_s > 0:
            raise ValueError(f"stale_timeout_s must be > 0, got {stale_timeout_s}")
        self.layout = layout
        self.clock: Clock = clock if clock is not None else SystemClock()
        self.stale_timeout_s = stale_timeout_s
        self.read_timeout_s = read_timeout_s
        self.counters = ReaderCounters()
        self._parser = FrameParser(layout, self.counters)
        self._baudrate = baudrate
        self._path: str | None = None
        if isinstance(port, str):
            self.port_name = port
            self._path = port
            self._serial: SerialLike = _open(port, baudrate, read_timeout_s)
        else:
            self.port_name = str(getattr(port, "port", None) or getattr(port, "name", "") or port)
            self._serial = port
        # decoded frames, no bytes: the simulator's fast path (FrameTransport)
        self._frames_in: FrameTransport | None = (
            port if hasattr(port, "take_frames") else None  # type: ignore[assignment]
        )
        self._last_arrival = self.clock.now()
        self._stale = False
        self.last_frame: Frame | None = None
        self._connected = True
        self._closed = False
        self._backoff = Backoff(*REOPEN_BACKOFF_S)
        self._idle = threading.Event()  # never set: a bounded wait while the port is down
        self.last_port_error = ""

    @classmethod
    def from_config(
        cls,
        port: str | SerialLike,
        sensor: SensorConfig,
        board: BoardConfig,
        clock: Clock | None = None,
    ) -> FrameReader:
        return cls(
            port,
            layout_from_config(sensor, board),
            baudrate=board.baudrate,
            clock=clock,
            stale_timeout_s=board.stale_timeout_s,
        )

    # -- reading -------------------------------------------------------------------------

    def poll(self) -> list[Frame]:
        """Parse whatever bytes are already waiting; never blocks, never raises on a lost
        port (it is counted and reopened later)."""
        if self._frames_in is not None:
            return self._arrived(self._parser.accept(self._frames_in.take_frames()))
        if not self._usable():
            return self._ingest(b"")
        try:
            waiting = self._serial.in_waiting
            data = self._serial.read(waiting) if waiting else b""
        except PORT_ERRORS as exc:
            self._lost(exc)
            data = b""
        return self._ingest(data)

    def read(self) -> list[Frame]:
        """Block up to the read timeout for the first byte, then parse all that is waiting.
        While the port is lost (and not yet reopened) wait that long and return nothing."""
        if self._frames_in is not None:  # in memory: there is nothing to wait for
            return self.poll()
        if not self._usable():
            self._idle.wait(self.read_timeout_s)
            return self._ingest(b"")
        try:
            data = self._serial.read(max(1, self._serial.in_waiting))
            waiting = self._serial.in_waiting
            if data and waiting:
                data += self._serial.read(waiting)
        except PORT_ERRORS as exc:
            self._lost(exc)
            data = b""
        return self._ingest(data)

    def read_frames(self, count: int, timeout_s: float) -> list[Frame]:
        """Read until ``count`` frames arrived or ``timeout_s`` of real time passed (I/O bound)."""
        frames: list[Frame] = []
        deadline = time.monotonic() + timeout_s
        while len(frames) < count and time.monotonic() < deadline:
            frames += self.read()
        return frames

    def read_bytes(self, total: int, timeout_s: float) -> list[Frame]:
        """Read until ``counters.bytes_received >= total`` or ``timeout_s`` of real time passed."""
        frames: list[Frame] = []
        deadline = time.monotonic() + timeout_s
        while self.counters.bytes_received < total and time.monotonic() < deadline:
            frames += self.read()
        return frames

    def _ingest(self, data: bytes) -> list[Frame]:
        return self._arrived(self._parser.feed(data) if data else [])

    def _arrived(self, frames: list[Frame]) -> list[Frame]:
        if frames:
            self._last_arrival = self.clock.now()
            self._stale = False
            self.last_frame = frames[-1]
            self._backoff.reset()
        else:
            self.check_stale()
        return frames

    # -- a lost port ---------------------------------------------------------------------

    @property
    def connected(self) -> bool:
        """False from a failed read until the port has been opened again."""
        return self._connected

    def _lost(self, exc: BaseException) -> None:
        """A read failed: count it, close the port, try to reopen it at the next call."""
        self.counters.port_errors += 1
        self.last_port_error = f"{type(exc).__name__}: {exc}"
        if self._connected:
            self._connected = False
            self._backoff.failed(self.clock.now())  # the wait doubles until frames flow
            with contextlib.suppress(Exception):
                self._serial.close()

    def _usable(self) -> bool:
        """Connected, or reopened now (when the back-off allows an attempt)."""
        if self._connected:
            return True
        if self._closed or not self._backoff.allows(self.clock.now()):
            return False
        try:
            self._reopen()
        except OPEN_ERRORS as exc:
            self.last_port_error = f"reopen: {exc}"
            self._backoff.failed(self.clock.now())  # the wait doubles until frames flow
            return False
        self._connected = True
        self.counters.reopens += 1
        return True

    def _reopen(self) -> None:
        if self._path is not None:
            self._serial = _open(self._path, self._baudrate, self.read_timeout_s)
            return
        opener = getattr(self._serial, "open", None)  # a pyserial object opens its port again
        if callable(opener) and not getattr(self._serial, "is_open", False):
            opener()

    # -- stream health -------------------------------------------------------------------

    def check_stale(self) -> bool:
        """True if no frame arrived within the stale timeout; counts each fresh->stale change."""
        if not self._stale and self.clock.now() - self._last_arrival > self.stale_timeout_s:
            self._stale = True
            self.counters.stale_events += 1
        return self._stale

    @property
    def stale(self) -> bool:
        return self.check_stale()

    @property
    def pending(self) -> int:
        return self._parser.pending

    # -- lifetime ------------------------------------------------------------------------

    def close(self) -> None:
        self._closed = True
        self._serial.close()

    def __enter__(self) -> FrameReader:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()


def _open(port: str, baudrate: int, timeout_s: float) -> SerialLike:
    try:
        return serial.serial_for_url(port, baudrate=baudrate, timeout=timeout_s)
    except OPEN_ERRORS as exc:
        raise SensorPortError(open_failure("board", port, exc)) from exc
