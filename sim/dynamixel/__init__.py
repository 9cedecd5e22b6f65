"""Dynamixel X-series servos emulated on a pseudo-terminal (Protocol 2.0).

``EmulatedBus([EmulatedServo(1, "XM430-W350"), ...], clock=clock)`` opened as a context manager
gives a port path the unmodified ``dynamixel_sdk`` can drive. Modules: :mod:`.protocol` (pure
framing), :mod:`.servo` (one servo's state and motion), :mod:`.bus` (the pty server thread).

Layering: nothing here imports ``robot/`` control code; the pure-data control table
:mod:`wire.dynamixel` is the one shared module (a hardware fact, kept in one place).
"""

from sim.dynamixel.bus import EmulatedBus
from sim.dynamixel.servo import EmulatedServo

__all__ = ["EmulatedBus", "EmulatedServo"]
