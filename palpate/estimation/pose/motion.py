"""How far the tissue moved along the sensor's axis during a trial, from the tip grating.

A trial touches the surface on the way in and leaves it on the way out. For tissue that stands
still (and is elastic) the tip grating's load crosses one small level at the same stage advance
both ways: the rig's compliances and the beam's shortening give the same travel at the same
load. Breathing, the heart or a patient's motion moves the surface in between: the advance at
the release is then the advance at the first touch less the surface's displacement toward the
sensor. So the motion is measured, not assumed: through a band of small loads
(``LEVEL_SIGMAS``: 5 to 15 times the load's noise above its zero, both from the approach's
records, the sensor free after the last zero; up to a quarter of the peak load at least, so a
fast retraction from stiff tissue still leaves records in it, and half of it where a branch
still has too few) a line of advance against load
on the way in (the first pass) and one on the way out (the retraction), the two advances at
the band's middle load apart. A line through the band, not one crossing: one record's noise
would move a crossing by its share of the band.

It sees the net displacement between the two instants; motion that comes back by the release
shows in the fit's residuals instead. Tissue that relaxes and recovers slowly releases early,
which reads as motion away from the sensor (docs/breathing.md).

Usage::

    motion = surface_motion(states, advance, tip_loads, times)  # None: not measured
    motion.moved, motion.velocity  # m and m/s toward the sensor
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..detect.contact import difference_sigma

LEVEL_SIGMAS = (5.0, 15.0)  # the band of loads read, in the load's noise above its zero
PEAK_SHARES = (0.25, 0.5)  # the band reaches this share of the peak load at least, the second
# where a branch has too few records in the first (a fast retraction passes a stiff tissue's 15
# sigma in a record or two; the heart's beat can hurry it further)
FREE_ROWS = 5  # the approach's records the zero and the noise need at least
FREE_STATE = "approach"
OUT_STATE = "retracting"
MIN_ROWS = 3  # a branch's records in the band a line needs at least


@dataclass(frozen=True)
class Motion:
    """The surface's displacement toward the sensor (m) between the first touch and the
    release, and when the two were (s, the band's middle load on each branch; NaN without the
    records' times)."""

    moved: float
    touch: float = math.nan
    release: float = math.nan
    sigma: float = 0.0  # m, the standard error of ``moved`` from the two lines' scatter

    @property
    def velocity(self) -> float:
        """m/s toward the sensor, as an even drift between the two (0 without their times)."""
        span = self.release - self.touch
        return self.moved / span if span > 0 else 0.0

    @property
    def velocity_sigma(self) -> float:
        """The standard error of :attr:`velocity` (m/s)."""
        span = self.release - self.touch
        return self.sigma / span if span > 0 else 0.0


def surface_motion(
    states: Sequence[str],
    advance: ArrayLike,
    loads: Sequence[float | None],
    times: Sequence[float] | None = None,
) -> Motion | None:
    """How far the surface moved toward the sensor between the first touch and the final
    release, from a trial's record (state, stage advance m, tip load N and time s per row, in
    order); None when the approach has too few records, or a branch too few in the band."""
    u = np.asarray(advance, dtype=np.float64)
    f = np.asarray([np.nan if x is None else x for x in loads], dtype=np.float64)
    t = np.full(u.shape, np.nan) if times is None else np.asarray(times, dtype=np.float64)
    s = np.asarray(states)
    keep = np.isfinite(u) & np.isfinite(f)
    free = free_load(s[keep], f[keep])
    if free is None:
        return None
    zero, sigma = free
    lo = zero + LEVEL_SIGMAS[0] * sigma
    peak = float(np.max(f[keep])) - zero
    out = s == OUT_STATE
    before_out = np.arange(s.size) < (int(np.argmax(out)) if out.any() else s.size)
    for share in PEAK_SHARES:
        hi = zero + max(LEVEL_SIGMAS[1] * sigma, share * peak)
        band = keep & (f >= lo) & (f <= hi)
        loading = band & before_out
        past = np.flatnonzero(keep & (f > hi) & before_out)
        if past.size:  # the first pass through the band: up to the load's first rise past it
            loading &= np.arange(s.size) < past[0]
        unloading = band & out
        if min(np.count_nonzero(loading), np.count_nonzero(unloading)) >= MIN_ROWS:
            return _between(u, t if times is not None else None, f, (loading, unloading), lo, hi)
    return None


def _between(
    u: np.ndarray,
    t: np.ndarray | None,
    f: np.ndarray,
    branches: tuple[np.ndarray, np.ndarray],
    lo: float,
    hi: float,
) -> Motion:
    """The motion between the loading and the unloading branch's lines at the band's middle."""
    middle = 0.5 * (lo + hi)
    (u_in, se_in), (u_out, se_out) = (_at(u[b], f[b], middle) for b in branches)
    sigma = math.hypot(se_in, se_out)
    if t is None:
        return Motion(u_in - u_out, sigma=sigma)
    touch, release = (_at(t[b], f[b], middle)[0] for b in branches)
    return Motion(u_in - u_out, touch, release, sigma)


def free_load(states: ArrayLike, loads: ArrayLike) -> tuple[float, float] | None:
    """The tip load's zero and noise (N) on the approach's rows (the sensor free after the last
    zero), None with fewer than ``FREE_ROWS`` of them."""
    f = np.asarray(loads, dtype=np.float64)
    free = f[(np.asarray(states) == FREE_STATE) & np.isfinite(f)]
    if free.size < FREE_ROWS:
        return None
    return float(np.median(free)), max(difference_sigma(free), float(free.std()))


def _at(x: np.ndarray, f: np.ndarray, load: float) -> tuple[float, float]:
    """x (the advance, or the time) at ``load`` on the line through a branch's (load, x),
    and its standard error from the line's scatter (0 with too few records for one)."""
    if np.ptp(f) <= 0:
        return float(np.mean(x)), 0.0
    slope, intercept = np.polyfit(f, x, 1)
    n = f.size
    if n <= 2:
        return float(intercept + slope * load), 0.0
    scatter = float(np.sum((x - intercept - slope * f) ** 2)) / (n - 2)
    leverage = 1.0 / n + (load - f.mean()) ** 2 / float(np.sum((f - f.mean()) ** 2))
    return float(intercept + slope * load), math.sqrt(scatter * leverage)
