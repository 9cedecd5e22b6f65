"""A Dynamixel bus on a pseudo-terminal: X-series servos answering Protocol 2.0 packets.

:class:`EmulatedBus` owns a set of :class:`sim.dynamixel.servo.EmulatedServo` and, once opened, a
pty whose slave path (``bus.port``) any Dynamixel tool or the unmodified ``dynamixel_sdk`` can
open like ``/dev/ttyUSB0``. A background thread reads the pty master, splits the stream into
packets (:mod:`sim.dynamixel.protocol`) and writes the status packets back at once.

Time: with a ``sim.clock.VirtualClock`` the servos move only when the clock advances (an
``on_advance`` listener), so tests and simulated trials never wait on the wall clock; without a
clock (``palpate emulate``) they move on wall time, brought up to date before every packet.

Answers follow the e-manual (:mod:`sim.dynamixel.instructions`, which this bus feeds the decoded
packets).

Bus timing: ideal by default (every reply at once). With ``timing`` (a
:class:`sim.dynamixel.timing.BusTiming`: baud rate, the servos' Return Delay Time, the USB
adapter's latency timer) and a virtual clock, the host gets each reply when a real U2D2 bus would
hand it over: the bus advances the clock to that time before the reply is seen (the host is
blocked on the read meanwhile). Without a clock (real time) the timing is not applied.

Layering: the control table comes from :mod:`wire.dynamixel`, the leaf the driver in ``robot/``
reads too; ``sim/`` never imports ``robot/``.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterable
from typing import Self

from ...config.schema import ServoBusConfig, XYStageConfig, servo_roster
from ...wire import dynamixel as tables
from ..clock import VirtualClock
from . import protocol
from .instructions import InstructionSet, Reply
from .pty import PtyLink
from .servo import EmulatedServo
from .timing import RETURN_DELAY_UNIT_S, BusTiming

_REALTIME_POLL_S = 0.01
_RETURN_DELAY_ADDRESS = tables.X_SERIES_CONTROL_TABLE["Return_Delay_Time"][0]


class EmulatedBus:
    """Servos on one emulated bus; a context manager that opens and closes the pty."""

    def __init__(
        self,
        servos: Iterable[EmulatedServo] = (),
        *,
        clock: VirtualClock | None = None,
        wall_time: Callable[[], float] = time.monotonic,
        timing: BusTiming | None = None,
    ) -> None:
        self._clock = clock
        self._wall_time = wall_time
        self.timing = timing
        self._line_free = 0.0  # bus time at which the line is idle (realistic timing)
        self._t0 = wall_time()
        self._servos: list[EmulatedServo] = []
        self._lock = threading.Lock()
        self._reader = protocol.PacketReader()
        self._link: PtyLink | None = None
        self.port = ""
        self.packets_handled = 0
        self._instructions = InstructionSet(self._servos)
        for servo in servos:
            self.add(servo)
        if clock is not None:
            clock.on_advance(self._on_clock)

    @classmethod
    def from_config(
        cls,
        cfg: ServoBusConfig,
        *,
        clock: VirtualClock | None = None,
        timing: BusTiming | None = None,
        stage: XYStageConfig | None = None,
    ) -> Self:
        """The three servos of the roller-gear drive with the IDs and models of ``cfg``, and the
        x-y stage's two when ``stage`` is given."""
        servos = [EmulatedServo(s.id, s.model) for s in servo_roster(cfg, stage).values()]
        return cls(servos, clock=clock, timing=timing)

    # --- the servos --------------------------------------------------------------------------
    def add(self, servo: EmulatedServo) -> EmulatedServo:
        with self._lock:
            if any(s.id == servo.id for s in self._servos):
                raise ValueError(f"a servo with id {servo.id} is already on the bus")
            servo.advance_to(self.now())
            self._servos.append(servo)
        return servo

    def servo(self, servo_id: int) -> EmulatedServo:
        """The servo answering to ``servo_id`` (the hook for the simulated world)."""
        found = self._instructions.find(servo_id)
        if found is None:
            raise KeyError(f"no servo with id {servo_id} on the bus")
        return found

    @property
    def servos(self) -> tuple[EmulatedServo, ...]:
        return tuple(self._servos)

    def now(self) -> float:
        """Bus time in s: the virtual clock's, or wall time since the bus was made
        (``wall_time``, ``time.monotonic`` unless a test passes its own)."""
        if self._clock is not None:
            return self._clock.now()
        return self._wall_time() - self._t0

    def _on_clock(self, t: float) -> None:
        # answer what already arrived first, so a goal written before the advance is honoured
        self._pump()
        self._advance_all(t)

    def _advance_all(self, t: float) -> None:
        for s in self._servos:
            s.advance_to(t)

    # --- packets -----------------------------------------------------------------------------
    def handle(self, data: bytes) -> bytes:
        """Feed bytes as if they came down the wire; returns the bytes the servos answer."""
        with self._lock:
            if self._clock is None:
                self._advance_all(self.now())
            replies: list[Reply] = []
            for packet in self._reader.feed(data):
                self.packets_handled += 1
                replies += self._instructions.dispatch(packet)
            out = [r.encode() for r in replies]
            due = self._timed(len(data), replies, out)
        self._wait_until(due)
        return b"".join(out)

    def exchange(self, packet: protocol.Packet) -> list[Reply]:
        """Answer one decoded request without bytes: the status packets as :class:`Reply`
        records, in the order they would go on the wire (``sim.dynamixel.direct``)."""
        with self._lock:
            if self._clock is None:
                self._advance_all(self.now())
            self.packets_handled += 1
            replies = self._instructions.dispatch(packet)
            due = None
            if self.timing is not None:  # sizes as on the wire: encode only to count the bytes
                raw = protocol.encode(packet.servo_id, packet.instruction, packet.params)
                due = self._timed(len(raw), replies, [r.encode() for r in replies])
        self._wait_until(due)
        return replies

    # --- bus timing (sim.dynamixel.timing) ---------------------------------------------------
    def _timed(self, request_bytes: int, replies: list[Reply], raw: list[bytes]) -> float | None:
        """When the host has these replies (None: at once, or nothing to wait for)."""
        timing = self.timing
        if timing is None or self._clock is None:
            return None
        answers = []
        for reply, packet in zip(replies, raw, strict=True):
            servo = self._instructions.find(reply.servo_id)
            units = 0 if servo is None else servo.memory[_RETURN_DELAY_ADDRESS]
            answers.append((len(packet), units * RETURN_DELAY_UNIT_S))
        self._line_free, due = timing.exchange(self.now(), self._line_free, request_bytes, answers)
        return due

    def _wait_until(self, due: float | None) -> None:
        """The host waits for its reply: virtual time runs on to ``due`` (outside the locks:
        the clock's listeners, this bus among them, run during the advance)."""
        if due is None or self._clock is None:
            return
        dt = due - self._clock.now()
        if dt > 0:
            self._clock.advance(dt)

    # --- the pseudo-terminal (sim.dynamixel.pty) ---------------------------------------------
    def open(self) -> str:
        """Create the pty and start answering; returns the port path (also ``self.port``)."""
        if self._link is None:
            idle = self._catch_up if self._clock is None else None
            self._link = PtyLink(self.handle, idle, _REALTIME_POLL_S)
            self.port = self._link.port
        return self.port

    def close(self) -> None:
        """Stop the thread and close the pty (idempotent)."""
        if self._link is not None:
            self._link.close()
            self._link = None

    def __enter__(self) -> Self:
        self.open()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _catch_up(self) -> None:
        """Real-time mode, nothing on the line: the servos move on to wall time."""
        with self._lock:
            self._advance_all(self.now())

    def _pump(self) -> None:
        if self._link is not None:
            self._link.pump()
