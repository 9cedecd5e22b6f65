"""Frames from the acquisition board over pyserial: the port, sequence gaps, staleness.

:class:`FrameReader` owns a serial transport (a device path, a pty, a pyserial URL such as
``loop://``, or an already open serial object), parses what arrives with
:class:`sensor.parser.FrameParser` (which counts what it rejects) and adds sequence-gap and
stale-stream detection on an injected :class:`~sensor.clock.Clock`.

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
from types import TracebackType
from typing import Protocol

import serial

from ..config.schema import BoardConfig, SensorConfig
from ..wire.frame import Frame, FrameLayout
from .clock import Clock, SystemClock
from .parser import FrameParser, ReaderCounters, layout_from_config
from .ports import OPEN_ERRORS, PORT_ERRORS, Backoff, open_failure

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
