"""Faults on the servo bus's reply path: packet loss, corrupt replies, a servo that goes silent.

:class:`FaultyBus` is an :class:`sim.dynamixel.bus.EmulatedBus` whose :meth:`FaultyBus.handle`
passes the servos' status packets through a fault filter, so the faults hit every path the bus
serves (the pty of ``--wire`` and the in-process port) and the servos still execute every request
they receive, as real servos do when only the return line is bad:

* ``loss_probability``: each status packet is lost (the driver sees a timeout);
* ``corrupt_probability``: each status packet gets one flipped byte (a CRC or framing error);
* :meth:`FaultyBus.mute`: one servo answers nothing until a time (a loose cable, a brown-out).

The servo's own hooks (``drop_replies``, ``corrupt_replies``, ``raise_hardware_error``,
``set_stalled``) stay where they are; this module only adds what they cannot express: faults by
probability and by time. Seeded: the same generator seed gives the same faults.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field

import numpy as np

from ...config.loader import limits
from ..clock import VirtualClock
from . import protocol
from .bus import EmulatedBus
from .servo import EmulatedServo
from .timing import BusTiming

_HEAD = len(protocol.HEADER) + 3  # header, id, two length bytes


@dataclass(frozen=True)
class PacketFaults:
    """Per status packet probabilities of loss and corruption (0 = off)."""

    loss_probability: float = field(default=0.0, metadata=limits(ge=0, le=1))
    corrupt_probability: float = field(default=0.0, metadata=limits(ge=0, le=1))

    def __post_init__(self) -> None:
        for name in ("loss_probability", "corrupt_probability"):
            p = getattr(self, name)
            if not 0.0 <= p <= 1.0:
                raise ValueError(f"{name} must be in [0, 1], got {p}")


@dataclass
class LinkStats:
    """What the filter did to the replies."""

    replies: int = 0
    lost: int = 0
    corrupted: int = 0
    muted: int = 0


def split_status_packets(data: bytes) -> list[bytes]:
    """Split the servos' reply bytes into whole packets (they are well formed by construction).

    Bytes that do not start with a Protocol 2.0 header, or a length running past the end, are
    returned as one last chunk, so nothing is lost by splitting.
    """
    out: list[bytes] = []
    i = 0
    n = len(data)
    while i < n:
        if data[i : i + len(protocol.HEADER)] != protocol.HEADER or n - i < _HEAD:
            out.append(data[i:])
            break
        end = i + _HEAD + (data[i + 5] | (data[i + 6] << 8))
        if end > n:
            out.append(data[i:])
            break
        out.append(data[i:end])
        i = end
    return out


class FaultyBus(EmulatedBus):
    """An emulated bus with a faulty return line. Faults are off until set."""

    def __init__(
        self,
        servos: Iterable[EmulatedServo] = (),
        *,
        clock: VirtualClock | None = None,
        wall_time: Callable[[], float] = time.monotonic,
        timing: BusTiming | None = None,
    ) -> None:
        super().__init__(servos, clock=clock, wall_time=wall_time, timing=timing)
        self.packet_faults = PacketFaults()
        self.link_stats = LinkStats()
        self._rng = np.random.default_rng(0)
        self._muted: dict[int, float] = {}
        # replaces the servos' whole reply (after the faults above); fuzzing drives it
        self.reply_filter: Callable[[bytes], bytes] | None = None

    def set_packet_faults(self, faults: PacketFaults, seed: int = 0) -> None:
        """Lose or corrupt status packets with these probabilities from now on."""
        self.packet_faults = faults
        self._rng = np.random.default_rng(seed)

    def mute(self, servo_id: int, until: float = math.inf) -> None:
        """The servo sends no status packet until bus time ``until`` (s); it still obeys."""
        self.servo(servo_id)  # KeyError for an unknown id
        self._muted[servo_id] = until

    def handle(self, data: bytes) -> bytes:
        reply = super().handle(data)
        f = self.packet_faults
        if reply and (self._muted or f.loss_probability or f.corrupt_probability):
            reply = b"".join(self._filter(p) for p in split_status_packets(reply))
        return reply if self.reply_filter is None else self.reply_filter(reply)

    def _filter(self, packet: bytes) -> bytes:
        s = self.link_stats
        s.replies += 1
        if len(packet) > 4 and packet[4] in self._muted:
            if self.now() < self._muted[packet[4]]:
                s.muted += 1
                return b""
            del self._muted[packet[4]]
        f = self.packet_faults
        if f.loss_probability and self._rng.random() < f.loss_probability:
            s.lost += 1
            return b""
        if f.corrupt_probability and self._rng.random() < f.corrupt_probability:
            s.corrupted += 1
            i = int(self._rng.integers(len(packet)))
            flip = int(self._rng.integers(1, 256))
            return packet[:i] + bytes([packet[i] ^ flip]) + packet[i + 1 :]
        return packet
