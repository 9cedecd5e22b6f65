"""The record read in the heart's quiet phase: an ECG-gated (stroboscopic) estimate.

Beside a strong beat (0.4-0.5 mm) the systole pushes the tissue past the depth at which the beam
buckles: the beam snaps through in every systole and springs back in diastole, and a fit of the
whole record must know the beat's shape to a hundredth of a millimetre (it does not: a heart's
beat is not three harmonics, and its rate swings). In mid-diastole the surface stands nearly
still, at the same place every beat (``estimation.pose.heartbeat.QUIET``). The indentation
machine judges buckling there and then holds the buckled beam through a few more quiet windows
(``robot.body``), so the record holds several windows in contact before the beam buckles with
the heart at rest, and several after.

The rows of those windows are the tissue's law with no beat in them, but for the breath hold's
drift (about 0.07 mm/s, as fast as the indentation). The drift is read from the record itself:
the buckled beam carries a nearly constant load, so in the windows after buckling its
shortening follows the surface, and the drift's velocity is the one at which the joint fit's
residual is least (:func:`strobe_fit`); the interval spans the fits 3 standard errors either
side. The band of small loads ``estimation.pose.motion`` reads cannot serve here: the release
falls at any phase of the beat.

Usage::

    strobe = strobed_rows(rows, times, tip_forces, pulses)  # None: too few quiet windows
    joint, motion = strobe_fit(strobe, times, drift=True, fit=fit)
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ..jointfit import JointFit
from ..jointfit.noise import MAX_RHO
from ..pose.heartbeat import in_quiet_phase, r_waves
from ..pose.motion import LEVEL_SIGMAS, Motion
from .motion import DRIFT_SIGMAS, Row, free_loads, least_residual, spanning, still_rows

OFF_BEAT = "off-beat"  # a row outside the quiet phase: no loading row (estimation.trial.states)
MIN_WINDOWS = 2  # quiet windows with the tip in contact before buckling: a law, not a point
MIN_BUCKLED = 2  # quiet windows with the beam buckled: the drift
TOUCHING = ("contact", "indenting")
HELD = 10e-6  # m: the stage stands within this of its last advance while buckled
BUCKLED = ("buckled", "holding")
DRIFT_SPAN = 0.5e-3  # m/s either way the drift's velocity is searched over (a hold: < 0.1 mm/s)
DRIFT_STEP = 0.01e-3  # m/s: the residual's curvature is read this far either side


@dataclass(frozen=True)
class Strobe:
    """The rows with those outside the quiet phase set aside, and the first quiet row in contact
    and the last held one (s): the span the drift is read over."""

    rows: list[Row]
    touch: float
    release: float


def strobed_rows(
    rows: list[Row],
    times: Sequence[float] | None,
    tip_forces: Sequence[float | None] | None,
    pulses: Sequence[float] | None,
) -> Strobe | None:
    """The rows with those outside the heart's quiet phase set aside (state ``OFF_BEAT``), the
    phase from the ticks (s) whose frames carried an ECG's R-wave pulse; None where fewer than
    ``MIN_WINDOWS`` quiet windows hold the tip in contact before buckling or fewer than
    ``MIN_BUCKLED`` hold the buckled beam still after it (:func:`held_rows`), or without times,
    tip loads or two R waves."""
    if times is None or not pulses or not tip_forces or len(tip_forces) != len(rows):
        return None
    beats = r_waves(times, pulses)
    if len(beats) < 2:
        return None
    found = free_loads(rows, tip_forces)
    if found is None:
        return None
    states, load, sigma = found
    quiet = in_quiet_phase(times, beats)
    touching = quiet & np.isin(states, TOUCHING) & (load > LEVEL_SIGMAS[1] * sigma)
    buckled = quiet & held_rows(rows)
    if _windows(times, beats, touching) < MIN_WINDOWS or _windows(times, beats, buckled) < (
        MIN_BUCKLED
    ):
        return None
    kept = [(s if q else OFF_BEAT, u, e) for (s, u, e), q in zip(rows, quiet, strict=True)]
    span = (times[int(np.argmax(touching))], times[int(np.flatnonzero(buckled)[-1])])
    return Strobe(kept, *span)


def held_rows(rows: list[Row]) -> np.ndarray:
    """Which rows hold the buckled beam still: buckled, at the stage's last advance while
    buckled (the post-buckling travel's end, within ``HELD``)."""
    states = np.asarray([r[0] for r in rows])
    advance = np.asarray([r[1] for r in rows], dtype=np.float64)
    buckled = np.isin(states, BUCKLED) & np.isfinite(advance)
    if not buckled.any():
        return buckled
    return np.asarray(buckled & (np.abs(advance - advance[buckled][-1]) <= HELD))


def _windows(times: Sequence[float], beats: Sequence[float], rows: np.ndarray) -> int:
    """The number of heart cycles ``rows`` (a mask) fall in."""
    return int(np.unique(np.searchsorted(np.asarray(beats), np.asarray(times)[rows])).size)


def strobe_fit(
    strobe: Strobe,
    times: Sequence[float],
    drift: bool,
    fit: Callable[[list[Row]], JointFit | None],
) -> tuple[JointFit | None, Motion | None]:
    """The joint fit ``fit`` of the quiet rows (:func:`strobed_rows`) and, with ``drift``, the
    drift's velocity where its residual is least, the interval spanning the fits at
    ``DRIFT_SIGMAS`` standard errors of it either side; the drift as a :class:`Motion` over the
    strobe's span. Failed where the least lies at the search's edge (the
    record does not fix the drift) or the residuals stay correlated to the cap (the quiet
    phase was not still)."""
    quiet, touch, release = strobe.rows, strobe.touch, strobe.release
    if not drift:
        return _trusted(fit(quiet)), None

    def at(v: float) -> JointFit | None:
        return fit(still_rows(quiet, times, v, touch))

    least = least_residual(at, (-DRIFT_SPAN, DRIFT_SPAN), DRIFT_STEP, DRIFT_STEP, 2 * DRIFT_STEP)
    best, sigma, joint, span = least.best, least.sigma, least.joint, release - touch
    motion = Motion(best * span, touch, release, sigma * span)
    if joint is None or math.isnan(sigma):
        why = "the record does not fix the breath hold's drift (its fit is best at the edge)"
        return JointFit(False, f"heartbeat: {why}"), motion
    spread = [at(best + k * sigma) for k in (-DRIFT_SIGMAS, DRIFT_SIGMAS)]
    return _trusted(spanning(joint, spread)), motion


def _trusted(joint: JointFit | None) -> JointFit | None:
    """``joint``, failed where its residuals stay correlated to the cap."""
    if joint is not None and joint.success and joint.rho >= MAX_RHO:
        why = f"the heart's quiet phase was not still (residuals correlated, lag-1 {joint.rho:.2f})"
        return JointFit(False, f"heartbeat: {why}", n_points=joint.n_points)
    return joint
