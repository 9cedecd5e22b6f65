"""SI views of a configuration's unit-suffixed fields: the one place a ``_mm`` becomes metres.

A YAML key carries its unit (``standoff_mm``); the code reads the SI value beside it::

    @dataclass(frozen=True)
    class CampaignConfig:
        standoff_mm: float = 1.0
        standoff = SI("standoff_mm", MM)      # campaign.standoff -> 0.001 (m)

``SI`` reads a number, ``SIOptional`` a number or None, ``SITuple`` a tuple of numbers. They are
not dataclass fields (no annotation): not in the YAML, not in ``to_mapping``.
"""

from __future__ import annotations

from typing import Any


class _View:
    def __init__(self, name: str, scale: float) -> None:
        self.name, self.scale = name, scale

    def __set_name__(self, owner: type, attribute: str) -> None:
        self.__doc__ = f"``{self.name}`` in SI units (x {self.scale:g})"

    def _value(self, obj: object) -> Any:
        return getattr(obj, self.name)


class SI(_View):
    """A number field in SI units."""

    def __get__(self, obj: object, owner: type | None = None) -> float:
        return float(self._value(obj)) * self.scale


class SIOptional(_View):
    """An optional number field in SI units (None stays None)."""

    def __get__(self, obj: object, owner: type | None = None) -> float | None:
        value = self._value(obj)
        return None if value is None else float(value) * self.scale


class SITuple(_View):
    """A tuple-of-numbers field in SI units."""

    def __get__(self, obj: object, owner: type | None = None) -> tuple[float, ...]:
        return tuple(float(v) * self.scale for v in self._value(obj))
