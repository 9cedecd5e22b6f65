"""Dynamixel X-series servos over the real ``dynamixel_sdk`` (Protocol 2.0).

The control table is plain data in :mod:`wire.dynamixel` (shared with the emulator in ``sim/``);
:mod:`.units` is the one place where SI meets servo units, :mod:`.driver` the bus driver.
"""
