"""The board's faults and statistics: what to inject, what happened, and the per-sample draws.

Faults (:class:`BoardFaults`, per sample, from a seeded generator): garbage bursts between frames,
one flipped bit, truncated frames, dropped frames (the sequence number still advances), stalls
(the board goes silent and takes no samples, so the sequence does not jump) and a disconnect
(the master is closed). Garbage bytes never contain the sync byte 0xA5, so the reader's expected
counters follow exactly from :class:`BoardStats`; sync-looking garbage is a parser unit test.

:class:`FaultInjector` draws from the generator in a fixed order per sample (stall; then drop,
garbage, corruption), so the same seed gives the same faults; it never draws when no random
fault is switched on. The stall's timing and the disconnect are the emulator's
(:mod:`sim.board.emulator`), which knows the sample times.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ...config.loader import limits
from ...wire.frame import SYNC

SYNC_BYTE = SYNC[0]


@dataclass(frozen=True)
class BoardFaults:
    """Fault injection; probabilities are per sample. Loadable with ``config.loader``."""

    garbage_probability: float = field(default=0.0, metadata=limits(ge=0, le=1))
    garbage_max_bytes: int = field(default=64, metadata=limits(ge=1, le=4096))
    bitflip_probability: float = field(default=0.0, metadata=limits(ge=0, le=1))
    truncate_probability: float = field(default=0.0, metadata=limits(ge=0, le=1))
    drop_probability: float = field(default=0.0, metadata=limits(ge=0, le=1))
    stall_probability: float = field(default=0.0, metadata=limits(ge=0, le=1))
    stall_s: float = field(default=0.5, metadata=limits(gt=0, le=60))
    disconnect_after_s: float | None = field(default=None, metadata=limits(ge=0))
    seed: int = 0

    def validate(self) -> None:
        if self.bitflip_probability + self.truncate_probability > 1:
            raise ValueError("bitflip_probability + truncate_probability must be <= 1")

    @property
    def random(self) -> bool:
        """Whether any per-sample random fault is switched on; if not, the board never draws
        from its fault generator (the draws would decide nothing)."""
        return bool(
            self.garbage_probability
            or self.bitflip_probability
            or self.truncate_probability
            or self.drop_probability
            or self.stall_probability
        )


@dataclass
class BoardStats:
    """What the board did; ``log`` holds ``(seq, outcome, detail)`` when recording is on.

    Outcomes: ``"sent"``, ``"dropped"``, ``"bitflip"`` (detail: byte offset), ``"truncate"``
    (detail: bytes kept) and ``"stall"`` (seq: the next sample's; detail: start time in us).
    """

    samples: int = 0
    frames_sent: int = 0
    frames_dropped: int = 0
    frames_corrupted: int = 0
    overruns: int = 0
    garbage_bursts: int = 0
    garbage_bytes: int = 0
    stalls: int = 0
    bytes_sent: int = 0
    disconnected: bool = False
    log: list[tuple[int, str, int]] = field(default_factory=list)


FrameMaker = Callable[[int, float], bytes]  # (seq, sample time s) -> the encoded frame


class FaultInjector:
    """The per-sample fault draws of one board, counted in its :class:`BoardStats`."""

    def __init__(self, faults: BoardFaults, stats: BoardStats, *, record: bool) -> None:
        faults.validate()
        self.faults = faults
        self.stats = stats
        self.record = record
        self.rng = np.random.default_rng(faults.seed)
        self._random = faults.random

    def log(self, seq: int, outcome: str, detail: int) -> None:
        if self.record:
            self.stats.log.append((seq, outcome, detail))

    def stalls(self, seq: int, ts: float) -> bool:
        """Whether the board stalls at sample time ``ts`` (``seq``: the next sample's)."""
        p = self.faults.stall_probability
        if p and self.rng.random() < p:
            self.stats.stalls += 1
            self.log(seq, "stall", round(ts * 1e6))
            return True
        return False

    def sample(self, seq: int, ts: float, make: FrameMaker) -> bytes:
        """The bytes that go out for sample ``seq`` at ``ts``: its frame from ``make`` (not
        called for a dropped frame), maybe corrupted, maybe after a garbage burst."""
        f = self.faults
        rng = self.rng
        if not self._random:  # nothing to draw for: send the frame
            data = make(seq, ts)
            self.log(seq, "sent", 0)
            self.stats.frames_sent += 1
            return data
        if f.drop_probability and rng.random() < f.drop_probability:
            self.log(seq, "dropped", 0)
            self.stats.frames_dropped += 1
            return b""
        data = make(seq, ts)
        out = b""
        if f.garbage_probability and rng.random() < f.garbage_probability:
            out = self._garbage()
        return out + self._corrupted(seq, data)

    def _corrupted(self, seq: int, data: bytes) -> bytes:
        """``data`` with one flipped bit, truncated, or as it is (one draw decides)."""
        f = self.faults
        rng = self.rng
        r = rng.random()
        if r < f.bitflip_probability:
            bit = int(rng.integers(len(data) * 8))
            corrupted = bytearray(data)
            corrupted[bit // 8] ^= 1 << (bit % 8)
            data = bytes(corrupted)
            self.log(seq, "bitflip", bit // 8)
            self.stats.frames_corrupted += 1
        elif r < f.bitflip_probability + f.truncate_probability:
            keep = int(rng.integers(1, len(data)))
            data = data[:keep]
            self.log(seq, "truncate", keep)
            self.stats.frames_corrupted += 1
        else:
            self.log(seq, "sent", 0)
            self.stats.frames_sent += 1
        return data

    def _garbage(self) -> bytes:
        n = int(self.rng.integers(1, self.faults.garbage_max_bytes + 1))
        raw = self.rng.integers(0, 255, size=n, dtype=np.uint8)
        raw[raw >= SYNC_BYTE] += 1  # 0..255 without 0xA5
        self.stats.garbage_bursts += 1
        self.stats.garbage_bytes += n
        return raw.tobytes()
