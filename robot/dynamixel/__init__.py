"""Dynamixel X-series servos over the real ``dynamixel_sdk`` (Protocol 2.0).

:mod:`.tables` is the control table as plain data (shared with the emulator in ``sim/``),
:mod:`.units` the one place where SI meets servo units, :mod:`.driver` the bus driver.
"""
