"""A sensor that passes an endoscope's working channel, and the moduli it can span.

A bronchoscope's working channel is 2.0-2.8 mm across; a tool passes it with a clearance (a
2.8 mm channel takes tools of about 2.6 mm). Everything that goes through must fit the passage
``diameter - clearance``: the tip sphere (2R), the beam's bundle (the fiber on its row of
wires: the diagonal of their bounding box) and the tip grating's element, which sits behind
the sphere within its diameter. :meth:`Lumen.space` restricts a design space to what fits (and
adds the largest tip that does); the rest of the design is unchanged.

A small sphere pushes the design against every limit at once, and one sensor may not span the
range. :func:`span_range` answers with the widest range one sensor can, from the lowest
modulus any sensor through the channel reaches, the checks that stop it on either side, and a
second sensor for the rest:

    >>> from palpate.sensor_design import DesignConstraints, DesignSpace
    >>> lumen = Lumen(2.8e-3)
    >>> span = span_range((1e3, 20e3), DesignConstraints(max_depth_ratio=1.0,
    ...                   tip_force_resolution=0.05e-3), lumen.space(DesignSpace()))
    >>> span.one_sensor, len(span.ranges) >= 1
    (False, True)

Each feasibility question is one grid search (``search.design_sensor``); the range's ends are
found by bisection on log E to ``tolerance`` (2 %: about 20 searches, a few seconds).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass

from .results import DesignResult
from .search import binding_checks, design_sensor
from .space import MM, DesignConstraints, DesignSpace

CLEARANCE = 0.2 * MM  # a 2.8 mm channel passes a 2.6 mm tool
TIP_STEP = 0.05 * MM  # the finest tip radius step a printed sphere is made to
TOLERANCE = 0.02  # relative, on the modulus range's ends
BISECTIONS = 12
LAW_DEPTH_RATIO = 1.0  # the contact law's tables end here (model-form bound 10 %)


@dataclass(frozen=True)
class Lumen:
    """An endoscope's working channel (m): its ``diameter`` and the ``clearance`` a tool needs."""

    diameter: float
    clearance: float = CLEARANCE

    def __post_init__(self) -> None:
        if not (math.isfinite(self.diameter) and self.diameter > 0):
            raise ValueError(f"the lumen's diameter must be > 0 m, got {self.diameter!r}")
        if not (math.isfinite(self.clearance) and 0 <= self.clearance < self.diameter):
            raise ValueError(
                f"the clearance must be in [0, diameter), got {self.clearance!r} m for a "
                f"{self.diameter * 1e3:g} mm lumen"
            )

    @property
    def passage(self) -> float:
        """The largest diameter (m) that passes: ``diameter - clearance``."""
        return self.diameter - self.clearance

    def largest_tip(self) -> float:
        """The largest tip radius (m) that passes, on the ``TIP_STEP`` grid."""
        return round(math.floor(self.passage / 2 / TIP_STEP + 1e-9) * TIP_STEP, 12)

    def space(self, space: DesignSpace) -> DesignSpace:
        """``space`` restricted to what passes: tips of 2R <= passage (with the largest that
        passes added) and wire diameters whose widest row under the largest fiber fits.
        ValueError when no tip or no wire passes."""
        tips = {r for r in space.tip_radii if 2 * r <= self.passage}
        if self.largest_tip() > 0:
            tips.add(self.largest_tip())
        if not tips:
            raise ValueError(f"no tip sphere passes a {self.diameter * 1e3:g} mm lumen")
        count = max(*space.wire_counts, 1)
        fiber = max(space.fiber_radii)
        wires = tuple(d for d in space.wire_diameters if bundle(fiber, count, d) <= self.passage)
        if not wires:
            raise ValueError(
                f"no wire row of {count} under a {fiber * 2e6:g} um fiber passes a "
                f"{self.diameter * 1e3:g} mm lumen"
            )
        return DesignSpace(
            fiber_radii=space.fiber_radii,
            fiber_modulus=space.fiber_modulus,
            wire_modulus=space.wire_modulus,
            wire_diameters=wires,
            wire_counts=space.wire_counts,
            tip_radii=tuple(sorted(tips)),
            length_range=space.length_range,
            length_step=space.length_step,
        )


def bundle(fiber_radius: float, wire_count: int, wire_diameter: float) -> float:
    """The diameter (m) of the circle around a fiber on a row of wires: the diagonal of the
    bounding box (width: the row or the fiber; height: a wire and the fiber)."""
    width = max(wire_count * wire_diameter, 2 * fiber_radius)
    height = 2 * fiber_radius + (wire_diameter if wire_count else 0.0)
    return math.hypot(width, height)


@dataclass(frozen=True)
class Span:
    """What the sensors through one channel cover of a requested modulus range (Pa).

    Attributes:
        requested: (E_min, E_max) asked for.
        ranges: the sensors' ranges, lowest first: the requested range when one sensor spans
            it; else the widest from the lowest reachable modulus, then a second sensor's; empty
            when no modulus of the range is reachable.
        designs: each range's design (the search's result).
        lowest_blocked: the checks that keep any sensor from the requested E_min
            (``search.binding_checks``: each alone; empty when it is reached).
        top_blocked: the checks that stop the first sensor's range from reaching further.
    """

    requested: tuple[float, float]
    ranges: tuple[tuple[float, float], ...]
    designs: tuple[DesignResult, ...]
    lowest_blocked: tuple[str, ...]
    top_blocked: tuple[str, ...]

    @property
    def one_sensor(self) -> bool:
        """One sensor spans the requested range."""
        return len(self.ranges) == 1 and self.ranges[0] == self.requested

    @property
    def covered(self) -> tuple[float, float] | None:
        """(lowest, highest) modulus the sensors cover, None when none does."""
        if not self.ranges:
            return None
        return self.ranges[0][0], self.ranges[-1][1]


def span_range(
    modulus_range: tuple[float, float],
    constraints: DesignConstraints,
    space: DesignSpace,
    *,
    tolerance: float = TOLERANCE,
) -> Span:
    """The sensors that cover ``modulus_range`` (Pa) under ``constraints`` with ``space`` (a
    lumen's, :meth:`Lumen.space`): see the module docstring and :class:`Span`."""
    lo, hi = modulus_range
    full = design_sensor(modulus_range, constraints, space)
    if full.success:
        return Span((lo, hi), ((lo, hi),), (full,), (), ())

    @functools.cache  # the bisections ask some ranges twice (the range's ends again)
    def search(a: float, b: float) -> DesignResult:
        return design_sensor((a, b), constraints, space)

    lowest_blocked: tuple[str, ...] = ()
    start = lo
    if not search(lo, lo).success:
        lowest_blocked = binding_checks((lo, lo), constraints, space)
        reachable = _first(lambda e: search(e, e).success, lo, hi, tolerance)
        if reachable is None:
            return Span((lo, hi), (), (), lowest_blocked, ())
        start = reachable
    top = _last(lambda e: search(start, e).success, start, hi, tolerance)
    first = search(start, top)
    if top >= hi:
        return Span((lo, hi), ((start, hi),), (first,), lowest_blocked, ())
    top_blocked = binding_checks((start, top * (1 + tolerance)), constraints, space)
    second_top = _last(lambda e: search(top, e).success, top, hi, tolerance)
    second = search(top, second_top)
    ranges = ((start, top), (top, second_top)) if second.success else ((start, top),)
    designs = (first, second) if second.success else (first,)
    return Span((lo, hi), ranges, designs, lowest_blocked, top_blocked)


def _first(ok: Callable[[float], bool], lo: float, hi: float, tolerance: float) -> float | None:
    """The smallest E in (lo, hi] with ``ok(E)``, to ``tolerance`` on log E, given ``ok(lo)``
    False; a coarse scan first (``ok`` need not hold all the way up), then bisection."""
    below = lo
    for k in range(1, 9):
        e = lo * (hi / lo) ** (k / 8)
        if ok(e):
            return _bisect(ok, below, e, tolerance, holds_at_low=False)
        below = e
    return None


def _last(ok: Callable[[float], bool], lo: float, hi: float, tolerance: float) -> float:
    """The largest E in [lo, hi] with ``ok(E)``, given ``ok(lo)``, to ``tolerance`` on log E."""
    if ok(hi):
        return hi
    return _bisect(ok, lo, hi, tolerance, holds_at_low=True)


def _bisect(
    ok: Callable[[float], bool], a: float, b: float, tolerance: float, *, holds_at_low: bool
) -> float:
    """Bisection on log E of [a, b], where ``ok`` holds at ``a`` (``holds_at_low``) or at ``b``
    and not at the other end; returns the bracket's end where it holds."""
    for _ in range(BISECTIONS):
        if b / a <= 1 + tolerance:
            break
        mid = math.sqrt(a * b)
        if ok(mid) == holds_at_low:
            a = mid
        else:
            b = mid
    return a if holds_at_low else b
