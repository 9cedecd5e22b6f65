"""What a real U2D2 bus costs in time: wire time, Return Delay Time, the FTDI latency timer.

The emulator answers at once by default (``bus_timing: ideal``). With a :class:`BusTiming`
(``bus_timing: realistic``) the emulated bus tells the host its replies when a real bus would
(:meth:`BusTiming.exchange`), on the simulator's virtual clock (never a wall-clock sleep):

1. the request leaves the host's USB adapter once the line is free and takes
   ``bits_per_byte / baudrate`` s per byte on the wire (8N1: 10 bits; 10 us at 1 Mbps);
2. each servo that answers waits its Return Delay Time (the Return_Delay_Time register, 2 us
   per unit: 500 us by default) after the line goes quiet, then sends its status packet (a sync
   read's servos answer one after the other, in the order of the request);
3. the FTDI chip of the U2D2 passes received bytes to the host in USB packets of 62 data bytes:
   a full packet goes at once, a partial one when the latency timer fires. The timer runs
   freely with its period (16 ms by default on Linux; 1 ms after
   ``echo 1 > /sys/bus/usb-serial/devices/ttyUSB0/latency_timer``), so the last bytes of a reply
   reach the host at the next multiple of the period on the bus clock.

A sync write gets no reply: the host goes on at once and the line stays busy until the packet has
been sent. So a read-modify cycle (one sync read, one sync write) costs about one latency period
when the timer is the bottleneck (16 ms: about 60 cycles/s), and the wire time plus the return
delays when it is not (1 ms at 1 Mbps: a cycle of about 2 ms).

Simplified: the USB OUT direction (host to adapter) takes no time; a reply that never comes
(a dropped packet) costs no time here (the SDK's timeout is wall time: it is not modelled);
the latency timer's phase starts at bus time 0 and is not reset by full packets.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

USB_PACKET_BYTES = 62  # data bytes in one 64-byte full-speed packet of an FT232 (2 status bytes)
RETURN_DELAY_UNIT_S = 2e-6  # Return_Delay_Time: 2 us per unit


@dataclass(frozen=True)
class BusTiming:
    """A U2D2-like adapter: baud rate (bit/s), latency timer (s), bits per byte on the wire."""

    baudrate: float = 1_000_000.0
    latency_timer_s: float = 16e-3
    bits_per_byte: int = 10

    def __post_init__(self) -> None:
        if not self.baudrate > 0 or not self.latency_timer_s > 0 or self.bits_per_byte < 1:
            raise ValueError(
                "bus timing: baudrate and latency_timer_s must be > 0, bits_per_byte >= 1; got "
                f"{self.baudrate}, {self.latency_timer_s}, {self.bits_per_byte}"
            )

    def wire_time(self, n_bytes: int) -> float:
        """Seconds to send ``n_bytes`` on the line."""
        return n_bytes * self.bits_per_byte / self.baudrate

    def exchange(
        self,
        t: float,
        line_free: float,
        request_bytes: int,
        replies: Sequence[tuple[int, float]],
    ) -> tuple[float, float | None]:
        """One request handed to the adapter at bus time ``t`` (s) while the line is busy until
        ``line_free``; ``replies``: (bytes, return delay s) of each status packet, in order.

        Returns (when the line is free again, when the host has the whole reply or None if
        nothing answers)."""
        end = max(t, line_free) + self.wire_time(request_bytes)
        if not replies:
            return end, None
        for n_bytes, delay in replies:
            end += delay + self.wire_time(n_bytes)
        total = sum(n for n, _ in replies)
        if total % USB_PACKET_BYTES == 0:  # the last byte fills a USB packet: sent at once
            return end, end
        period = self.latency_timer_s
        # the next firing of the free-running timer (a hair of tolerance for float rounding)
        return end, math.ceil(end / period - 1e-9) * period

    def read_modify_rate(
        self, request_bytes: int, reply_bytes: Sequence[int], delay_s: float, write_bytes: int
    ) -> float:
        """Cycles per second of: sync read (``request_bytes``; replies of ``reply_bytes`` each
        after ``delay_s``), then a sync write of ``write_bytes``, repeated (steady state)."""
        t, line, cycles = 0.0, 0.0, 50
        first = 0.0
        for k in range(cycles + 1):
            line, got = self.exchange(t, line, request_bytes, [(n, delay_s) for n in reply_bytes])
            if got is None:
                raise ValueError("read_modify_rate needs at least one reply")
            t = got
            if k == 0:
                first = t
            line, _ = self.exchange(t, line, write_bytes, [])
        return cycles / (t - first)
