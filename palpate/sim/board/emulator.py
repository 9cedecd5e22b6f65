"""The acquisition-board emulator: frames on a pseudo-terminal (or a byte sink) on a clock.

The emulator owns the pty master and writes frames to it; a reader opens the slave path
(:attr:`BoardEmulator.port`) with pyserial exactly as it would open the real board. Each sample
comes from a caller-supplied source ``source(t) -> BoardSample`` (the simulator's world).

Two ways to run:

- on a virtual clock (``clock=VirtualClock``): on every clock advance the emulator emits the
  samples whose times fall in the elapsed interval ``(t_prev, t]``; nothing depends on wall time;
- free-running (``clock=None``): a thread emits samples in real time (``palpate emulate``).

Three ways out: a pty (the hardware path), a byte sink (``sink``: encoded frames in memory), or
a frame sink (``frame_sink``: the frames themselves, range-checked as :func:`wire.frame.encode`
would, never encoded; for the simulator's fast path, where nothing needs the bytes). A frame sink
cannot carry the byte-level faults (drops, garbage, bit flips, truncation, stalls): those need
bytes, and the constructor says so.

Writes go through a writer thread, so a clock advance never blocks on a full pty buffer; a
bounded queue models the board's transmit buffer (when full, samples are dropped and the next
frame carries ``Status.OVERRUN``). The faults are drawn per sample by
:class:`sim.board.faults.FaultInjector`; the stall's duration and the disconnect are timed here.
"""

from __future__ import annotations

import contextlib
import math
import os
import pty
import queue
import select
import threading
import time
import tty
from types import TracebackType
from typing import Any, Protocol

import numpy as np

from ...wire.frame import Frame, FrameLayout, Status, check_ranges, encode, frame_from_si
from ..clock import VirtualClock
from .faults import BoardFaults, BoardStats, FaultInjector
from .source import SampleSource

EMIT_SLACK_S = 1e-7  # s: a sample this close to the clock's time is due (see emit_until)


class ByteSink(Protocol):
    """Where the fast path writes frames instead of a pty (``sim.inprocess.MemorySerial``)."""

    @property
    def name(self) -> str: ...

    def write(self, data: bytes) -> int: ...


class FrameSink(Protocol):
    """Where the fast path puts frames without encoding them (``sim.inprocess.FramePipe``)."""

    @property
    def name(self) -> str: ...

    def put_frames(self, frames: list[Frame]) -> None: ...


class BoardEmulator:
    """The board on a pty: ``with BoardEmulator(source, layout, clock=vc) as board: board.port``."""

    def __init__(
        self,
        source: SampleSource,
        layout: FrameLayout,
        *,
        rate_hz: float = 1000.0,
        clock: VirtualClock | None = None,
        faults: BoardFaults | None = None,
        record: bool = False,
        queue_chunks: int = 4096,
        sink: ByteSink | None = None,
        frame_sink: FrameSink | None = None,
    ) -> None:
        if not rate_hz > 0:
            raise ValueError(f"rate_hz must be > 0, got {rate_hz}")
        if frame_sink is not None and (sink is not None or (faults and faults.random)):
            raise ValueError("a frame sink takes no byte sink and no byte-level board faults")
        self._frame_sink = frame_sink
        self.source = source
        self.layout = layout
        self.rate_hz = float(rate_hz)
        self.clock = clock
        self.faults = faults if faults is not None else BoardFaults()
        self.stats = BoardStats()
        self._injector = FaultInjector(self.faults, self.stats, record=record)
        self._queue: queue.Queue[bytes | None] = queue.Queue(maxsize=queue_chunks)
        self._lock = threading.Lock()
        self._running = False
        self._stop = threading.Event()
        self._threads: list[threading.Thread] = []
        self._sink = sink
        self._in_process = sink is not None or frame_sink is not None
        if not self._in_process:
            self._master, self._slave = pty.openpty()
            tty.setraw(self._slave)  # no echo, no CR/LF mapping, no signals: bytes pass as they are
            os.set_blocking(self._master, False)  # the writer polls: stop() never hangs on a write
            self.port: str = os.ttyname(self._slave)
        else:  # the in-process fast path: frames go straight into the sink, no pty, no thread
            self._master = self._slave = -1
            self.port = str(getattr(frame_sink or sink, "name", "memory"))
        self._t0 = 0.0
        self._next = 1  # index of the next sample time t0 + k / rate
        self._seq = 0
        self._resume_at = -math.inf
        self._overrun = False
        self._closed = False
        if clock is not None:
            clock.on_advance(self._on_advance)

    @property
    def record(self) -> bool:
        """Whether ``stats.log`` records every sample's outcome."""
        return self._injector.record

    # -- lifetime ------------------------------------------------------------------------

    def start(self) -> BoardEmulator:
        """Start streaming: sample k is taken at ``t_start + k / rate_hz``, k = 1, 2, ..."""
        if self._running:
            return self
        if self._closed:
            raise RuntimeError("board emulator was stopped; create a new one")
        self._t0 = self.clock.now() if self.clock is not None else time.monotonic()
        self._running = True
        if not self._in_process:
            writer = threading.Thread(target=self._write_loop, name="board-writer", daemon=True)
            self._threads.append(writer)
            writer.start()
        if self.clock is None:
            gen = threading.Thread(target=self._free_run, name="board-clock", daemon=True)
            self._threads.append(gen)
            gen.start()
        return self

    def stop(self) -> None:
        """Stop streaming, join the threads and close the pty."""
        with self._lock:
            self._running = False
        self._stop.set()
        self._signal_writer()
        for t in self._threads:
            t.join(timeout=5.0)
        self._threads.clear()
        self._close_fds()
        self._closed = True

    def disconnect(self) -> None:
        """Unplug: the writer closes the pty after what is already queued (reads then fail)."""
        with self._lock:
            self._running = False
            self.stats.disconnected = True
        self._signal_writer()

    def __enter__(self) -> BoardEmulator:
        return self.start()

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.stop()

    # -- sample generation ---------------------------------------------------------------

    def _on_advance(self, t: float) -> None:
        self.emit_until(t)

    def _free_run(self) -> None:
        period = 1.0 / self.rate_hz
        while not self._stop.is_set() and self._running:
            self.emit_until(time.monotonic())
            self._stop.wait(min(max(period, 1e-4), 2e-3))

    def emit_until(self, t: float) -> int:
        """Emit every sample with time in ``(t_prev, t]``; returns how many samples were taken."""
        with self._lock:
            if not self._running:
                return 0
            # a sample is due within EMIT_SLACK_S of its time: a virtual clock that sums ticks
            # drifts by ~1e-15 s per tick, and the frame due now must not wait for the next call
            due = math.floor((t - self._t0 + EMIT_SLACK_S) * self.rate_hz)
            chunks: list[Any] = []  # encoded frames, or frames for a frame sink
            taken = 0
            sent_before = self.stats.frames_sent
            disconnect_at = self.faults.disconnect_after_s
            while self._next <= due:
                ts = self._t0 + self._next / self.rate_hz
                self._next += 1
                if disconnect_at is not None and ts - self._t0 >= disconnect_at:
                    self._running = False
                    self.stats.disconnected = True
                    break
                if ts < self._resume_at:
                    continue
                if self._injector.stalls(self._seq, ts):
                    self._resume_at = ts + self.faults.stall_s
                    continue
                chunks.append(self._sample(ts))
                taken += 1
            intact = self.stats.frames_sent - sent_before
            stop_after = not self._running
            if self._frame_sink is not None:
                self._frame_sink.put_frames(chunks)
                chunks = []
        data = b"".join(chunks)
        if data:
            self._enqueue(data, intact)
        if stop_after:
            self._signal_writer()
        return taken

    def _sample(self, ts: float) -> bytes | Frame:
        seq = self._seq
        self._seq = (seq + 1) % 2**32
        self.stats.samples += 1
        if self._frame_sink is not None:  # no byte faults here (checked in the constructor)
            frame = self.frame_of(seq, ts)
            check_ranges(frame)
            self._injector.log(seq, "sent", 0)
            self.stats.frames_sent += 1
            return frame
        return self._injector.sample(seq, ts, self._frame)

    def _frame(self, seq: int, ts: float) -> bytes:
        """The encoded frame of sample ``seq`` taken at ``ts`` from the source."""
        return self._encode(self.frame_of(seq, ts))

    def frame_of(self, seq: int, ts: float) -> Frame:
        """The frame of sample ``seq`` taken at ``ts`` from the source, as the board sends it
        (its layout's fields, the source's flags; what a recording of the stream holds)."""
        s = self.source(ts)
        flags = s.flags | (Status.OVERRUN if self._overrun else 0)
        self._overrun = False
        wavelengths = s.wavelengths
        if not isinstance(wavelengths, tuple | np.ndarray):
            wavelengths = tuple(wavelengths)
        frame = frame_from_si(
            seq,
            ts,
            s.encoder,
            wavelengths,
            reference=s.reference if self.layout.has_reference else None,
            force=s.force if self.layout.has_force else None,
            flags=flags,
            tip=s.tip if self.layout.has_tip else None,
        )
        layout = frame.layout
        if layout is not self.layout and layout != self.layout:
            raise ValueError(f"source gave {layout}, the board streams {self.layout}")
        return frame

    def _encode(self, frame: Frame) -> bytes:
        return encode(frame)

    def _enqueue(self, data: bytes, intact: int) -> None:
        if self._sink is not None:
            self._sink.write(data)
            with self._lock:
                self.stats.bytes_sent += len(data)
            return
        try:
            self._queue.put_nowait(data)
        except queue.Full:  # the transmit buffer is full: the chunk is lost, as on a real board
            with self._lock:
                self.stats.overruns += 1
                self.stats.frames_sent -= intact
                self.stats.frames_dropped += intact
                self._overrun = True
            return
        with self._lock:
            self.stats.bytes_sent += len(data)

    def _signal_writer(self) -> None:
        while True:
            try:
                self._queue.put_nowait(None)
                return
            except queue.Full:
                with contextlib.suppress(queue.Empty):
                    self._queue.get_nowait()

    # -- writing -------------------------------------------------------------------------

    def _write_loop(self) -> None:
        while True:
            data = self._queue.get()
            if data is None:
                break
            if not self._write_all(data):
                break
        if self.stats.disconnected:
            self._close_fds()

    def _write_all(self, data: bytes) -> bool:
        view = memoryview(data)
        while view:
            if self._stop.is_set():
                return False
            try:
                view = view[os.write(self._master, view) :]
            except BlockingIOError:
                select.select([], [self._master], [], 0.05)
            except OSError:
                return False
        return True

    def _close_fds(self) -> None:
        with self._lock:
            fds = [fd for fd in (self._master, self._slave) if fd >= 0]
            self._master = self._slave = -1
        for fd in fds:
            with contextlib.suppress(OSError):
                os.close(fd)
