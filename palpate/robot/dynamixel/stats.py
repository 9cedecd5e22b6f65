"""What a servo bus did, measured: the counters :class:`robot.dynamixel.driver.DynamixelBus`
keeps in wall time, from which its packet timeout and retries are sized (docs/transport-and-
scale.md has the measured figures: an idle host and a host whose two cores are busy).

Usage::

    bus = DynamixelBus.from_config(cfg)
    ...
    print(bus.stats.as_dict())  # transactions, retries, failures, replies by latency
"""

from __future__ import annotations

import bisect
import dataclasses
from dataclasses import dataclass, field

GOALS_WRITE = "sync write of goals"  # the driver's name of a tick's goal write
REPLY_BINS_MS = (1.0, 2.0, 5.0, 10.0, 20.0, 50.0)
"""Upper edges (ms) of the reply-latency histogram; one more bin holds everything slower."""


@dataclass
class BusStats:
    """Transactions that succeeded, attempts beyond the first that a missed or corrupt status
    packet cost (``retries``), transactions that failed every attempt (``failures``; of them
    the goals' writes, ``write_failures``: a tick that holds its last goal), the
    slowest successful transaction (s, from its first attempt to its reply, retries included)
    and every answered attempt's latency by bin (:data:`REPLY_BINS_MS`)."""

    transactions: int = 0
    retries: int = 0
    failures: int = 0
    write_failures: int = 0  # of the failures, the goals' sync writes (the rest: reads)
    worst_latency: float = 0.0
    worst_reply: float = 0.0  # s, the slowest single attempt that was answered
    replies: list[int] = field(default_factory=lambda: [0] * (len(REPLY_BINS_MS) + 1))

    def answered(self, attempt: float, transaction: float) -> None:
        """An attempt answered after ``attempt`` s, its transaction ``transaction`` s after
        its first attempt."""
        self.transactions += 1
        self.worst_latency = max(self.worst_latency, transaction)
        self.worst_reply = max(self.worst_reply, attempt)
        self.replies[bisect.bisect_left(REPLY_BINS_MS, attempt * 1e3)] += 1

    def failed(self, what: str) -> None:
        """A transaction failed every attempt; ``what`` names it (the driver's words)."""
        self.failures += 1
        self.write_failures += what.startswith(GOALS_WRITE)

    def since(self, before: BusStats) -> BusStats:
        """The counts added since ``before`` (a copy taken earlier); the worst figures are the
        session's so far."""
        return BusStats(
            self.transactions - before.transactions,
            self.retries - before.retries,
            self.failures - before.failures,
            self.write_failures - before.write_failures,
            self.worst_latency,
            self.worst_reply,
            [a - b for a, b in zip(self.replies, before.replies, strict=True)],
        )

    def copy(self) -> BusStats:
        return dataclasses.replace(self, replies=list(self.replies))

    def as_dict(self) -> dict[str, object]:
        """JSON-ready, latencies in ms; ``replies_ms`` maps each bin's upper edge to its count
        (``"inf"``: slower than the last edge)."""
        edges = [f"{e:g}" for e in REPLY_BINS_MS] + ["inf"]
        return {
            "transactions": self.transactions,
            "retries": self.retries,
            "failures": self.failures,
            "write_failures": self.write_failures,
            "worst_latency_ms": self.worst_latency * 1e3,
            "worst_reply_ms": self.worst_reply * 1e3,
            "replies_ms": dict(zip(edges, self.replies, strict=True)),
        }
