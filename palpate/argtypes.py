"""Argument types for the commands' options: numbers with a range, checked when the command line
is parsed, so a bad value is one line naming the option (exit 2, argparse's usage error) before
anything runs. Every numeric option of every command takes one of these (``tests/test_options.py``
tries each with a negative number, zero, NaN, infinity and text)::

    parser.add_argument("--poisson", type=float_in(0.0, 0.5, high_open=True), default=0.45)
    parser.add_argument("--tip-radii-mm", type=number_list(positive_float), default="1,2")
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable


def int_at_least(low: int) -> Callable[[str], int]:
    """An integer option that must be >= ``low`` (``--workers``: 1, ``--seed``: 0)."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
        if value < low:
            raise argparse.ArgumentTypeError(f"must be >= {low}, got {value}")
        return value

    parse.__name__ = f"integer >= {low}"
    return parse


def _number(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None


def positive_float(text: str) -> float:
    """A finite number > 0 (``--seconds``)."""
    value = _number(text)
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text}")
    return value


def non_negative_float(text: str) -> float:
    """A finite number >= 0 (``--clearance-mm``, ``--imperfection``)."""
    value = _number(text)
    if not (math.isfinite(value) and value >= 0):
        raise argparse.ArgumentTypeError(f"must be a finite number >= 0, got {text}")
    return value


def positive_or_inf(text: str) -> float:
    """A number > 0, ``inf`` allowed (``--thickness-mm``: inf is a half-space)."""
    value = _number(text)
    if not value > 0:  # NaN fails too
        raise argparse.ArgumentTypeError(f"must be a number > 0 (inf: unbounded), got {text}")
    return value


def float_in(
    low: float, high: float, *, low_open: bool = False, high_open: bool = False
) -> Callable[[str], float]:
    """A number in [low, high], either end open (``--confidence``: (0, 1))."""
    left, right = "(" if low_open else "[", ")" if high_open else "]"

    def parse(text: str) -> float:
        value = _number(text)
        above = value > low if low_open else value >= low
        below = value < high if high_open else value <= high
        if not (above and below):  # NaN fails both
            raise argparse.ArgumentTypeError(
                f"must be in {left}{low:g}, {high:g}{right}, got {text}"
            )
        return value

    parse.__name__ = f"number in {left}{low:g}, {high:g}{right}"
    return parse


def number_list(item: Callable[[str], float]) -> Callable[[str], tuple[float, ...]]:
    """Comma-separated numbers, each checked by ``item`` (``--tip-radii-mm 1,2.5,4``)."""

    def parse(text: str) -> tuple[float, ...]:
        values = tuple(item(v.strip()) for v in text.split(",") if v.strip())
        if not values:
            raise argparse.ArgumentTypeError(f"expected comma-separated numbers, got {text!r}")
        return values

    parse.__name__ = f"list of {getattr(item, '__name__', 'numbers')}"
    return parse


def number_range(item: Callable[[str], float]) -> Callable[[str], tuple[float, float]]:
    """``MIN:MAX``, each checked by ``item``, MIN <= MAX (``--modulus-range 1:20``)."""

    def parse(text: str) -> tuple[float, float]:
        parts = text.split(":")
        if len(parts) != 2:
            raise argparse.ArgumentTypeError(f"expected MIN:MAX, got {text!r}")
        lo, hi = item(parts[0]), item(parts[1])
        if lo > hi:
            raise argparse.ArgumentTypeError(f"need MIN <= MAX, got {text!r}")
        return lo, hi

    parse.__name__ = f"range of {getattr(item, '__name__', 'numbers')}"
    return parse


positive_int = int_at_least(1)
non_negative_int = int_at_least(0)


def port_number(text: str) -> int:
    """A TCP port, 0-65535 (0: any free port) (``--live``)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a port number, got {text!r}") from None
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"a port is 0-65535 (0: any free one), got {value}")
    return value
