"""Virtual time for the simulator: ``sleep`` advances time instead of waiting.

Listeners registered with :meth:`VirtualClock.on_advance` are called with the new time after
every advance, which is how the emulated servos and board move their state forward.
"""

from __future__ import annotations

import threading
from collections.abc import Callable


class VirtualClock:
    """A monotonic simulated clock; thread-safe; satisfies ``sensor.clock.Clock``."""

    def __init__(self, start: float = 0.0) -> None:
        self._t = float(start)
        self._lock = threading.Lock()
        self._listeners: list[Callable[[float], None]] = []

    def now(self) -> float:
        with self._lock:
            return self._t

    def advance(self, dt: float) -> float:
        """Move time forward by ``dt`` >= 0 seconds and notify listeners; returns the new time."""
        if not dt >= 0:
            raise ValueError(f"dt must be >= 0, got {dt}")
        with self._lock:
            self._t += dt
            t = self._t
            listeners = list(self._listeners)
        for listener in listeners:
            listener(t)
        return t

    def sleep(self, dt: float) -> None:
        if dt > 0:
            self.advance(dt)

    def on_advance(self, listener: Callable[[float], None]) -> None:
        with self._lock:
            self._listeners.append(listener)
