"""The heart's beat in a record: the surface's motion along the axis, periodic in the phase an
ECG monitor's R waves give (frame status bit 7), measured from the tip grating's load.

Between R waves the phase runs evenly (``phi = 2 pi (t - R_k) / (R_k+1 - R_k)``; past the last
one at the median period), and the surface lifts ``h = a cos(phi) + b sin(phi)`` toward the
sensor. A tip pressed ``d = x + h - x0`` into tissue pushes back about as ``d^1.5``, so in contact
``P^(2/3)`` is linear in the stage's advance ``x`` and in ``cos(phi)``, ``sin(phi)``: one least
squares gives ``a`` and ``b`` in metres (:func:`heartbeat`). That lag (the phase of ``h``) is
sharp; the amplitude reads 10-40 % small where the tissue's law is not Hertz's, the tip loses
contact in the troughs or the surface drifts, and the trial's joint fit sets it
(``estimation.trial.motion``).

Usage::

    beat = heartbeat(advance, load, times, beats, contact=load > 5 * sigma)
    beat.amplitude, beat.lift(times)      # m: half the beat's peak-to-peak, the lift per row
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]
MIN_ROWS = 20  # contact rows the least squares needs
MIN_BEATS = 2  # R waves: a period


def r_waves(times: Sequence[float], pulses: Sequence[float]) -> tuple[float, ...]:
    """The R waves (s): the first tick of each pulse, from ``pulses``, the ticks (s) whose frames
    carried the sync bit, and ``times``, every tick's (a pulse spans several ticks).

    >>> r_waves([0.0, 0.1, 0.2, 0.3, 0.4, 0.5], [0.1, 0.2, 0.5])
    (0.1, 0.5)
    """
    on = set(pulses)
    out, previous = [], False
    for t in times:
        now = t in on
        if now and not previous:
            out.append(float(t))
        previous = now
    return tuple(out)


@dataclass(frozen=True)
class Heartbeat:
    """The surface's lift with the heart: ``cos`` and ``sin`` (m) of the phase the R waves
    ``beats`` (s) give; ``sigma``: the amplitude's standard error (m, 0: not known)."""

    beats: tuple[float, ...]
    cos: float = 0.0
    sin: float = 0.0
    sigma: float = 0.0

    @property
    def period(self) -> float:
        """s, the median R-R interval."""
        return float(np.median(np.diff(self.beats)))

    @property
    def amplitude(self) -> float:
        """m: half the beat's peak-to-peak along the axis."""
        return math.hypot(self.cos, self.sin)

    def phase(self, t: ArrayLike) -> FloatArray:
        """rad at ``t`` (s), from the R wave before (the first one's period before the first)."""
        t = np.asarray(t, dtype=np.float64)
        r = np.asarray(self.beats)
        k = np.clip(np.searchsorted(r, t, side="right") - 1, 0, len(r) - 1)
        intervals = np.diff(r)
        span = np.where(k < len(intervals), intervals[np.minimum(k, len(intervals) - 1)], 0.0)
        span = np.where(span > 0, span, self.period)
        return np.asarray(2.0 * np.pi * (t - r[k]) / span, dtype=np.float64)

    def lift(self, t: ArrayLike) -> FloatArray:
        """m toward the sensor at ``t`` (s), about the beat's mean."""
        phi = self.phase(t)
        return self.cos * np.cos(phi) + self.sin * np.sin(phi)

    def scaled(self, factor: float, sigma: float = 0.0) -> Heartbeat:
        """The same lag, the amplitude times ``factor``, its standard error ``sigma`` (m)."""
        return dataclasses.replace(self, cos=self.cos * factor, sin=self.sin * factor, sigma=sigma)


def heartbeat(
    advance: ArrayLike,
    load: ArrayLike,
    times: ArrayLike,
    beats: Sequence[float],
    contact: ArrayLike,
) -> Heartbeat | None:
    """The beat (:class:`Heartbeat`) from the rows in ``contact`` (advance m, tip load N, time
    s) and the R waves ``beats`` (s); None with fewer than ``MIN_BEATS`` R waves or
    ``MIN_ROWS`` contact rows, or where the load does not rise with the advance."""
    if len(beats) < MIN_BEATS:
        return None
    x, p, t = (np.asarray(v, dtype=np.float64) for v in (advance, load, times))
    m = np.asarray(contact, dtype=bool) & np.isfinite(x) & np.isfinite(p) & (p > 0)
    if int(m.sum()) < MIN_ROWS:
        return None
    beat = Heartbeat(tuple(float(b) for b in beats))
    phi = beat.phase(t[m])
    y = p[m] ** (2.0 / 3.0)
    design = np.column_stack([x[m] - x[m].mean(), np.cos(phi), np.sin(phi), np.ones(phi.size)])
    coef, *_ = np.linalg.lstsq(design, y, rcond=None)
    slope = float(coef[0])
    if not slope > 0:
        return None
    return dataclasses.replace(beat, cos=float(coef[1]) / slope, sin=float(coef[2]) / slope)
