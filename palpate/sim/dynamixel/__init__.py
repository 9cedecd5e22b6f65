"""Dynamixel X-series servos emulated on a pseudo-terminal (Protocol 2.0).

``EmulatedBus([EmulatedServo(1, "XM430-W350"), ...], clock=clock)`` opened as a context manager
gives a port path the unmodified ``dynamixel_sdk`` can drive. Modules: :mod:`.protocol` (pure
framing), :mod:`.registers` (one servo's control table and its write rules), :mod:`.motion`
(the motion profiles), :mod:`.servo` (one servo: instructions, fault hooks, motion on the
clock), :mod:`.bus` (the pty server thread), :mod:`.faults` (a faulty return line).

Layering: the control table is :mod:`wire.dynamixel` (a hardware fact kept in one place, which
the driver in ``robot/`` reads too); nothing here imports ``robot/``.
"""

from .bus import EmulatedBus
from .servo import EmulatedServo

__all__ = ["EmulatedBus", "EmulatedServo"]
