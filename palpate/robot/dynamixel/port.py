"""The servo bus's port: the SDK's port handler with our reply timeout, and the bookkeeping that
opens a lost port again.

A port that fails under the driver (a USB adapter unplugged: pyserial's EIO or "readiness to
read but returned no data") is counted (``port_errors``), closed, and opened again with a
back-off in wall time (``reopens`` counts the successes); the driver's transactions fail as
transport errors meanwhile. The driver owns when to call :meth:`PortRecovery.lose` and
:meth:`PortRecovery.ready`.
"""

from __future__ import annotations

import contextlib
import time
from typing import Any

import dynamixel_sdk as sdk

from ...sensor.ports import OPEN_ERRORS, PORT_ERRORS, Backoff

REOPEN_BACKOFF_S = (0.02, 1.0)  # first and longest wall-time wait between reopening attempts


class TimedPortHandler(sdk.PortHandler):  # type: ignore[misc]  # the SDK is untyped
    """The SDK's port with a configurable reply timeout instead of its fixed 2 x 16 ms + 2 ms."""

    def __init__(self, port_name: str, timeout_ms: float) -> None:
        super().__init__(port_name)
        self.reply_timeout_ms = timeout_ms

    def setPacketTimeout(self, packet_length: int) -> None:
        self.packet_start_time = self.getCurrentTime()
        self.packet_timeout = self.tx_time_per_byte * packet_length + self.reply_timeout_ms


class PortRecovery:
    """Whether the port is lost, why, and when the next attempt to reopen it may run."""

    def __init__(self, port: Any, baudrate: int) -> None:
        self._port = port
        self._baudrate = baudrate
        self.port_errors = 0  # transactions that failed in the port itself (it was lost)
        self.reopens = 0  # times a lost port was opened again
        self.backoff = Backoff(*REOPEN_BACKOFF_S)  # wall time between reopening attempts
        self.lost = ""  # why the port is down ("" while it works)

    def lose(self, exc: Exception) -> None:
        """Count a failed port, close it and allow an attempt to reopen it at once."""
        self.port_errors += 1
        self.lost = str(exc) or type(exc).__name__
        self.backoff.reset()
        with contextlib.suppress(*PORT_ERRORS):
            self._port.closePort()

    def ready(self) -> bool:
        """True when the port works, or was lost and has just been opened again (an attempt
        runs only when the back-off allows it)."""
        if not self.lost:
            return True
        now = time.monotonic()
        if not self.backoff.allows(now):
            return False
        try:
            opened = bool(self._port.openPort() and self._port.setBaudRate(self._baudrate))
        except OPEN_ERRORS as exc:
            self.lost, opened = str(exc) or type(exc).__name__, False
        if not opened:
            self.backoff.failed(now)
            return False
        self.lost = ""
        self.reopens += 1
        return True
