"""One servo's control table in memory: item access by name, and the rules a write must pass.

The table is data (:mod:`wire.dynamixel`: name -> (address, size), the read-only items, the
value ranges, each model's items and power-on values); this module only reads it. Items are
little-endian, signed where the hardware is signed. A write answers the documented error
numbers: Access (a read-only item, an item the model lacks, a byte outside every item, the
EEPROM area below address 64 while torque is on), Data Length (part of an item), Data Range
(a value out of its range, an operating mode the model lacks), Limit (a goal beyond the
position or velocity limit) and Result Fail (torque on while a shutdown error is latched).

Not thread-safe by itself: :class:`sim.dynamixel.servo.EmulatedServo` holds its lock around
every call.
"""

from __future__ import annotations

import bisect
import struct
from collections.abc import Callable
from typing import Final

from ...wire import dynamixel as tables

_Unpack = Callable[[bytes | bytearray, int], tuple[int]]
_Pack = Callable[[bytearray, int, int], None]
_UNSIGNED_FORMATS: Final = {1: "<B", 2: "<H", 4: "<I"}

TORQUE_ENABLE: Final = tables.X_SERIES_CONTROL_TABLE["Torque_Enable"][0]
OPERATING_MODE: Final = tables.X_SERIES_CONTROL_TABLE["Operating_Mode"][0]


def model_name(model: str | int) -> str:
    """The model's name, from its name or its model number (ValueError if unknown)."""
    if isinstance(model, int):
        if model not in tables.MODEL_NAMES:
            raise ValueError(f"unknown model number {model}; known: {sorted(tables.MODEL_NAMES)}")
        return tables.MODEL_NAMES[model]
    if model not in tables.MODEL_NUMBERS:
        raise ValueError(f"unknown model {model!r}; known: {sorted(tables.MODEL_NUMBERS)}")
    return model


def _unpacker(name: str, size: int) -> _Unpack:
    """Reads an item's value, signed where the hardware is (``struct``: no slice, no copy)."""
    fmt = _UNSIGNED_FORMATS[size]
    return struct.Struct(fmt.lower() if name in tables.SIGNED else fmt).unpack_from


# The table looked up once, not per access (tens of item accesses per control tick):
# name -> (address, reader); name -> (address, writer of the value masked to its size, mask).
_READERS: Final[dict[str, tuple[int, _Unpack]]] = {
    name: (address, _unpacker(name, size))
    for name, (address, size) in tables.X_SERIES_CONTROL_TABLE.items()
}
_WRITERS: Final[dict[str, tuple[int, _Pack, int]]] = {
    name: (address, struct.Struct(_UNSIGNED_FORMATS[size]).pack_into, (1 << (8 * size)) - 1)
    for name, (address, size) in tables.X_SERIES_CONTROL_TABLE.items()
}


class ControlTable:
    """The control table of one servo of ``model``: ``memory`` and the items in it."""

    def __init__(self, model: str) -> None:
        self.model = model
        self._table = tables.control_table(model)
        self._items = sorted((a, s, n) for n, (a, s) in self._table.items())
        self._starts = [a for a, _, _ in self._items]
        # (address, size) of a whole item -> the item: a write of exactly one item, the usual
        # case, needs no search for the items it overlaps
        self._whole = {(a, size): (a, size, n) for a, size, n in self._items}
        self._covered = bytearray(tables.TABLE_SIZE)  # 1 where an item of the table lives
        for a, size, _ in self._items:
            self._covered[a : a + size] = b"\x01" * size
        self.memory = bytearray(tables.TABLE_SIZE)

    def get(self, name: str) -> int:
        address, unpack = _READERS[name]
        return unpack(self.memory, address)[0]

    def set(self, name: str, value: int) -> None:
        address, pack, mask = _WRITERS[name]
        pack(self.memory, address, int(value) & mask)

    def reset(self, *, eeprom: bool, keep: tuple[str, ...]) -> None:
        """Items to their power-on values: RAM, and the EEPROM area if ``eeprom``; not ``keep``."""
        defaults = tables.MODEL_DEFAULTS[self.model]
        for name, (address, _) in self._table.items():
            if (address < tables.EEPROM_END and not eeprom) or name in keep:
                continue
            self.set(name, defaults.get(name, 0))

    def read(self, address: int, length: int) -> tuple[int, bytes]:
        """``(error number, data)`` for a Read of ``length`` bytes at ``address``."""
        if length < 1 or address < 0 or address + length > tables.TABLE_SIZE:
            return tables.ERR_ACCESS, b""
        return 0, bytes(self.memory[address : address + length])

    def check_write(self, address: int, data: bytes) -> int:
        """The error number a Write of ``data`` at ``address`` would answer (0 if allowed)."""
        end = address + len(data)
        if not data or address < 0 or end > tables.TABLE_SIZE:
            return tables.ERR_ACCESS
        torque_on = self.memory[TORQUE_ENABLE] == 1
        for a, size, name in self._overlapping(address, end):
            if a < address or a + size > end:
                return tables.ERR_DATA_LENGTH
            if name in tables.READ_ONLY or (a < tables.EEPROM_END and torque_on):
                return tables.ERR_ACCESS
            value = _READERS[name][1](data, a - address)[0]  # signed where the item is
            error = self._check_value(name, value)
            if error:
                return error
        if 0 in self._covered[address:end]:
            return tables.ERR_ACCESS  # a byte outside every item
        return 0

    def store(self, address: int, data: bytes) -> None:
        """Write ``data`` at ``address`` item by item (after :meth:`check_write` allowed it)."""
        for a, size, _ in self._overlapping(address, address + len(data)):
            self.memory[a : a + size] = data[a - address : a - address + size]

    def _overlapping(self, address: int, end: int) -> list[tuple[int, int, str]]:
        """The items that share a byte with ``[address, end)``, in address order."""
        whole = self._whole.get((address, end - address))
        if whole is not None:
            return [whole]
        i = max(bisect.bisect_right(self._starts, address) - 1, 0)
        j = bisect.bisect_left(self._starts, end, lo=i)
        return [it for it in self._items[i:j] if it[0] + it[1] > address]

    def _check_value(self, name: str, value: int) -> int:
        bounds = tables.VALUE_RANGES.get(name)
        if bounds is not None and not bounds[0] <= value <= bounds[1]:
            return tables.ERR_DATA_RANGE
        if name == "Operating_Mode" and value not in tables.OPERATING_MODES[self.model]:
            return tables.ERR_DATA_RANGE
        if (
            name == "Torque_Enable"
            and value == 1
            and self.get("Hardware_Error_Status") & self.get("Shutdown")
        ):
            return tables.ERR_RESULT_FAIL
        if name == "Goal_Position":
            mode = self.get("Operating_Mode")
            if mode == tables.MODE_POSITION:
                lo, hi = self.get("Min_Position_Limit"), self.get("Max_Position_Limit")
            else:
                lo, hi = -tables.EXTENDED_POSITION_LIMIT, tables.EXTENDED_POSITION_LIMIT
            if not lo <= value <= hi:
                return tables.ERR_DATA_LIMIT
        if name == "Goal_Velocity" and abs(value) > self.get("Velocity_Limit"):
            return tables.ERR_DATA_LIMIT
        return 0
