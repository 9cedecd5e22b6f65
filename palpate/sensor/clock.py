"""The clock interface the control code runs on: wall time on hardware, virtual time in sim.

Control code (``robot/``, ``sensor/``) only calls ``now()`` and ``sleep(dt)``. On hardware that is
:class:`SystemClock`; the simulator passes ``sim.clock.VirtualClock``, whose ``sleep`` advances
simulated time instantly, so no test or simulated trial waits on the wall clock.
"""

from __future__ import annotations

import time
from typing import Protocol


class Clock(Protocol):
    def now(self) -> float:
        """Seconds on a monotonic clock."""
        ...

    def sleep(self, dt: float) -> None:
        """Let ``dt`` seconds pass (block on hardware, advance time in simulation)."""
        ...


class SystemClock:
    """Monotonic wall time."""

    def now(self) -> float:
        return time.monotonic()

    def sleep(self, dt: float) -> None:
        if dt > 0:
            time.sleep(dt)
