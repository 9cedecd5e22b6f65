"""The emulated bus's pseudo-terminal: a thread that answers the packets written to it.

:class:`PtyLink` owns the pty and its serving thread for :class:`sim.dynamixel.bus.EmulatedBus`:
the thread waits on the master side, hands every chunk of bytes to the bus (``handle``) and
writes the answer back at once. Without a virtual clock it also lets the bus bring its servos up
to wall time every ``poll_s`` while nothing arrives (``idle``), as ``palpate emulate`` needs.
"""

from __future__ import annotations

import os
import select
import threading
import tty
from collections.abc import Callable


class PtyLink:
    """A pty whose slave path (:attr:`port`) any Dynamixel tool can open like /dev/ttyUSB0."""

    def __init__(
        self,
        handle: Callable[[bytes], bytes],
        idle: Callable[[], None] | None = None,
        poll_s: float = 0.01,
    ) -> None:
        self._handle = handle
        self._idle = idle
        self._poll_s = poll_s
        # re-entrant: with realistic bus timing, answering a packet advances the virtual clock,
        # whose listener pumps the pty again from the same thread
        self._io_lock = threading.RLock()
        master, slave = os.openpty()
        tty.setraw(slave)
        os.set_blocking(master, False)
        stop_r, stop_w = os.pipe()
        self._fds: tuple[int, int, int, int] | None = (master, slave, stop_r, stop_w)
        self.port = os.ttyname(slave)
        self._thread = threading.Thread(
            target=self._serve, name=f"dynamixel-emulator {self.port}", daemon=True
        )
        self._thread.start()

    def close(self) -> None:
        """Stop the thread and close the pty (idempotent)."""
        fds = self._fds
        if fds is None:
            return
        master, slave, stop_r, stop_w = fds
        os.write(stop_w, b"x")
        self._thread.join(timeout=5.0)
        with self._io_lock:
            self._fds = None
        for fd in (master, slave, stop_r, stop_w):
            os.close(fd)

    def _serve(self) -> None:
        fds = self._fds
        if fds is None:
            return
        master, _, stop_r, _ = fds
        poll = self._poll_s if self._idle is not None else None
        while True:
            ready, _, _ = select.select([master, stop_r], [], [], poll)
            if stop_r in ready:
                return
            if master in ready:
                self.pump()
            elif self._idle is not None:
                self._idle()

    def pump(self) -> None:
        """Answer every packet waiting on the pty master (non-blocking)."""
        with self._io_lock:
            fds = self._fds
            if fds is None:
                return
            master = fds[0]
            while True:
                try:
                    data = os.read(master, 4096)
                except (BlockingIOError, OSError):
                    return
                if not data:
                    return
                view = memoryview(self._handle(data))
                while view:
                    try:
                        view = view[os.write(master, view) :]
                    except BlockingIOError:
                        select.select([], [master], [], 1.0)
