"""The heart's beat in a record: the surface's motion along the axis, periodic in the phase an
ECG monitor's R waves give (frame status bit 7), measured from the tip grating's load.

Between R waves the phase runs evenly (``phi = 2 pi (t - R_k) / (R_k+1 - R_k)``; past the last
one at the median period), and the surface lifts ``h = sum_k a_k cos(k phi) + b_k sin(k phi)``
toward the sensor, ``HARMONICS`` of them: a heart's beat is not a sine (a fast systole, a slow
diastole: a quarter of its motion beyond the first harmonic). A tip pressed ``d = x + h - x0``
into tissue pushes back about as ``d^1.5``, so in contact ``P^(2/3)`` is linear in the stage's
advance ``x`` and in each ``cos(k phi)``, ``sin(k phi)``: one least squares gives every ``a_k``
and ``b_k`` in metres (:func:`heartbeat`). The beat's shape and lag are sharp; its amplitude
reads 10-40 % small where the tissue's law is not Hertz's, the tip loses contact in the troughs
or the surface drifts, and the trial's joint fit sets it (``estimation.trial.motion``).

Usage::

    beat = heartbeat(advance, load, times, beats, contact=load > 5 * sigma)
    beat.amplitude, beat.lift(times)      # m: half the beat's peak-to-peak, the lift per row
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]
MIN_ROWS = 20  # contact rows the least squares needs
MIN_BEATS = 2  # R waves: a period
HARMONICS = 3  # of the beat's period: 97 % of a heart's motion (sim.heart), 99.6 % of its power
PEAK_GRID = 256  # phases the beat's peak to peak is read at
# the heart's quiet phase, of the R-R interval after an R wave: mid-diastole, after the rapid
# filling and before the atria's kick (cardiac CT reconstructs at 70-80 % of it for a still heart)
QUIET = (0.72, 0.90)


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


def in_quiet_phase(
    times: ArrayLike, beats: Sequence[float], window: tuple[float, float] = QUIET
) -> NDArray[np.bool_]:
    """Which ``times`` (s) lie in the heart's quiet phase (``window`` of the R-R interval after
    the R wave before; none before the first R wave). ``beats``: two R waves (s) at least.

    >>> in_quiet_phase([0.5, 1.8, 2.3], [0.0, 1.0, 2.0]).tolist()
    [False, True, False]
    """
    t = np.asarray(times, dtype=np.float64)
    share = Heartbeat(tuple(beats)).phase(t) / (2.0 * np.pi)
    return np.asarray((t >= beats[0]) & (share >= window[0]) & (share <= window[1]))


@dataclass(frozen=True)
class Heartbeat:
    """The surface's lift with the heart: ``cos[k]`` and ``sin[k]`` (m) of ``k + 1`` times the
    phase the R waves ``beats`` (s) give; ``sigma``: the amplitude's standard error (m, 0: not
    known)."""

    beats: tuple[float, ...]
    cos: tuple[float, ...] = ()
    sin: tuple[float, ...] = ()
    sigma: float = 0.0
    fixed: bool = True  # False: the record did not fix the amplitude (estimation.trial.motion)

    @property
    def period(self) -> float:
        """s, the median R-R interval."""
        return float(np.median(np.diff(self.beats)))

    @property
    def amplitude(self) -> float:
        """m: half the beat's peak-to-peak along the axis."""
        if not self.cos:
            return 0.0
        wave = self._wave(np.linspace(0.0, 2.0 * np.pi, PEAK_GRID, endpoint=False))
        return 0.5 * float(np.ptp(wave))

    def _wave(self, phi: FloatArray) -> FloatArray:
        out = np.zeros_like(phi)
        for k, (a, b) in enumerate(zip(self.cos, self.sin, strict=True), start=1):
            out += a * np.cos(k * phi) + b * np.sin(k * phi)
        return out

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
        return self._wave(self.phase(t))

    def scaled(self, factor: float, sigma: float = 0.0) -> Heartbeat:
        """The same shape and lag, the amplitude times ``factor``, its standard error ``sigma``
        (m)."""
        cos, sin = (tuple(c * factor for c in cs) for cs in (self.cos, self.sin))
        return dataclasses.replace(self, cos=cos, sin=sin, sigma=sigma)


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
    waves = [f(k * phi) for k in range(1, HARMONICS + 1) for f in (np.cos, np.sin)]
    design = np.column_stack([x[m] - x[m].mean(), *waves, np.ones(phi.size)])
    coef, *_ = np.linalg.lstsq(design, y, rcond=None)
    slope = float(coef[0])
    if not slope > 0:
        return None
    per = [float(c) / slope for c in coef[1:-1]]
    return dataclasses.replace(beat, cos=tuple(per[0::2]), sin=tuple(per[1::2]))
