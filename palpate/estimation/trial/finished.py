"""What the estimates read of a finished trial, whatever ran it: the marks the state machine set
and the record of its rows (``robot.trial.run.TrialResult`` is one, a log read back another).
And the tip grating's load at a record's buckling mark (the verdict's)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from enum import Enum
from typing import Protocol

Rows = Sequence[tuple[str, float, Sequence[float]]]


class Marks(Protocol):
    """The encoder marks of a trial (``robot.plan.TrialMarks``)."""

    @property
    def x_contact(self) -> float | None: ...
    @property
    def x_buckling(self) -> float | None: ...
    @property
    def strains_at_buckling(self) -> tuple[float, ...]: ...


class FinishedTrial(Protocol):
    """A finished trial as the estimates read it: its ending (``state``, ``reason``), its marks
    and its rows (state, advance m, strains), each row's time (s) and tip-grating load (N), and
    the ticks (s) whose frames carried an ECG's R-wave pulse."""

    @property
    def state(self) -> Enum: ...
    @property
    def reason(self) -> str: ...
    @property
    def marks(self) -> Marks: ...
    @property
    def record(self) -> list[tuple[str, float, tuple[float, ...]]]: ...
    @property
    def times(self) -> list[float]: ...
    @property
    def tip_forces(self) -> list[float]: ...
    @property
    def beats(self) -> list[float]: ...


def tip_load_at_buckling(rows: Rows, tip_forces: Sequence[float | None] | None) -> float | None:
    """The tip grating's load (N) at the first row past the buckling mark, None without one.

    >>> tip_load_at_buckling([("loading", 0.0, ()), ("buckled", 1e-3, ())], [0.1, 0.25])
    0.25
    """
    if not tip_forces or len(tip_forces) != len(rows):
        return None
    for (state, _, _), f in zip(rows, tip_forces, strict=True):
        if state == "buckled":
            return None if f is None or not math.isfinite(f) else float(f)
    return None
