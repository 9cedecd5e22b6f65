"""In-process transports: the fast path that skips the pseudo-terminals, nothing else.

- :class:`InProcessPort` is a ``dynamixel_sdk.PortHandler`` whose bytes go straight to an
  :class:`sim.dynamixel.bus.EmulatedBus` instead of a serial port: the real SDK still builds and
  parses every Protocol 2.0 packet and the real driver still runs; only the pty is gone.
- :class:`MemorySerial` is a byte pipe with the pyserial calls the frame reader uses
  (``in_waiting``, ``read``, ``close``); the board emulator writes encoded frames into it.
- :class:`FramePipe` hands the board emulator's frames to the frame reader as they are, with no
  encoding and no parsing (the simulator's fast path, where nothing needs the bytes); the reader
  still counts them and checks their sequence (``sensor.reader.FrameReader``).

The register-level servo path (no packets at all) is ``sim.dynamixel.direct``.

Tests run the same trial on both paths and compare the results.
"""

from __future__ import annotations

import threading
from typing import Any

import dynamixel_sdk as sdk

from ..wire.frame import Frame
from .dynamixel.bus import EmulatedBus


class InProcessPort(sdk.PortHandler):  # type: ignore[misc]  # the SDK is untyped
    """A dynamixel-sdk port wired to an emulated bus in this process."""

    def __init__(self, bus: EmulatedBus, name: str = "inprocess://dynamixel") -> None:
        super().__init__(name)
        self.bus = bus
        self._rx = bytearray()
        self.reply_timeout_ms = 20.0

    def openPort(self) -> bool:
        return self.setBaudRate(self.baudrate)

    def closePort(self) -> None:
        self.is_open = False

    def clearPort(self) -> None:
        self._rx.clear()

    def setBaudRate(self, baudrate: int) -> bool:
        self.baudrate = baudrate
        self.tx_time_per_byte = (1000.0 / baudrate) * 10.0
        self.is_open = True
        return True

    def getBytesAvailable(self) -> int:
        return len(self._rx)

    def readPort(self, length: int) -> bytes:
        out = bytes(self._rx[:length])
        del self._rx[:length]
        return out

    def writePort(self, packet: Any) -> int:
        data = bytes(packet)
        self._rx += self.bus.handle(data)
        return len(data)

    def setPacketTimeout(self, packet_length: int) -> None:
        self.packet_start_time = self.getCurrentTime()
        self.packet_timeout = self.tx_time_per_byte * packet_length + self.reply_timeout_ms


class MemorySerial:
    """A thread-safe in-memory byte pipe with the serial calls the frame reader needs."""

    def __init__(self, name: str = "memory://board") -> None:
        self.name = name
        self.port = name
        self._buf = bytearray()
        self._lock = threading.Lock()
        self.closed = False

    def write(self, data: bytes) -> int:
        with self._lock:
            self._buf += data
        return len(data)

    @property
    def in_waiting(self) -> int:
        with self._lock:
            return len(self._buf)

    def read(self, size: int = 1) -> bytes:
        with self._lock:
            out = bytes(self._buf[:size])
            del self._buf[:size]
        return out

    def close(self) -> None:
        self.closed = True


class FramePipe:
    """A thread-safe in-memory frame queue: a board emulator's frame sink and a frame reader's
    transport (``take_frames``); as a serial object it never has bytes waiting."""

    def __init__(self, name: str = "memory://board-frames") -> None:
        self.name = name
        self.port = name
        self._frames: list[Frame] = []
        self._lock = threading.Lock()
        self.closed = False

    def put_frames(self, frames: list[Frame]) -> None:
        with self._lock:
            self._frames += frames

    def take_frames(self) -> list[Frame]:
        with self._lock:
            out, self._frames = self._frames, []
        return out

    @property
    def in_waiting(self) -> int:
        return 0

    def read(self, size: int = 1) -> bytes:
        return b""

    def close(self) -> None:
        self.closed = True
