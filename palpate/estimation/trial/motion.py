"""The surface's motion in a trial's record (``estimation.pose.motion``): measured from the tip
grating, taken out of the record as an even drift, its uncertainty carried into the interval.

A ventilator's breath hold drifts (about 1 mm through a 15 s hold): the surface comes toward the
sensor while it indents, which a fit of a still surface reads as a stiffer tissue (+15 to +35 %
on the breath-hold scene). The motion between the first touch and the release, over the time
between them, is the drift's velocity; the record's advance taken against the surface
(:func:`still_rows`) is what a still surface would have given. The velocity's own error (the
two lines' scatter; on the breath-hold scene the errors spread 1.7 times wider than it says,
the records not being independent) is carried by fitting again at ``DRIFT_SIGMAS`` standard
errors either side (:func:`drift_envelope`): the interval spans the three.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar  # type: ignore[import-untyped,unused-ignore]

from ..jointfit import JointFit
from ..jointfit.noise import MAX_RHO
from ..pose.heartbeat import Heartbeat, heartbeat, r_waves
from ..pose.motion import LEVEL_SIGMAS, Motion, free_load, surface_motion

Row = tuple[str, float, Sequence[float]]
JointOf = Callable[[list[Row]], JointFit | None]
DRIFT_SIGMAS = 3.0
# A beat read larger than this many times the record's deepest indentation is not the heart's:
# the fit has traded the beat's amplitude for the modulus (a low modulus under a beat of tens of
# mm moves the load as a true modulus under the true beat does). On fresh scenes of
# docs/invivo.md the estimates with a beat in contact read 0.5-0.9 times the depth; those past 5
# times read 50-95 % low.
MAX_BEAT_OVER_DEPTH = 2.0
HEART_SCALES = (0.4, 3.0)  # of the least squares' amplitude (which reads 10-40 % small where
# the beat is a sine, up to 55 % where a heart's systole is the only contact a beat gives)
HEART_STEP = 0.05  # of it: the residual's curvature is read this far either side
HEART_FLOOR = 0.10  # the amplitude's standard error at least (of it): the residual's minimum
# lies 0-10 % below the true amplitude on the scenes of docs/invivo.md (the law's form), up to
# 25 % below where the hold's drift is as fast as the indentation (a soft sample's long contact)
HEART_EDGE = 0.02  # of the least squares' amplitude: a best this near the search's edge is not
# a minimum (the residual still falls past it: a stiff sample's record of two beats, the beam
# buckled by the systole; its estimate read 0.1-0.3 of the truth where the edge was taken)
HEART_ROWS = ("contact", "indenting")  # rows whose load is the tissue's (not the buckled beam's)


def record_motion(
    rows: Sequence[Row],
    tip_forces: Sequence[float | None] | None,
    times: Sequence[float] | None = None,
) -> Motion | None:
    """The surface's motion along the axis over a record (``estimation.pose.motion``), None without
    a tip grating."""
    if not tip_forces or len(tip_forces) != len(rows):
        return None
    return surface_motion([r[0] for r in rows], [r[1] for r in rows], tip_forces, times)


def still_rows(rows: list[Row], times: Sequence[float], velocity: float, touch: float) -> list[Row]:
    """The rows with the stage's advance taken against a surface drifting ``velocity`` (m/s
    toward the sensor): as if it stood where it was at ``touch`` (s)."""
    if velocity == 0.0:
        return rows
    return [(s, u + velocity * (t - touch), e) for (s, u, e), t in zip(rows, times, strict=True)]


def drift_envelope(
    joint: JointFit | None,
    rows: list[Row],
    times: Sequence[float],
    motion: Motion,
    fit: Callable[[list[Row]], JointFit | None],
) -> JointFit | None:
    """``joint`` (the fit of ``rows`` taken against ``motion``'s drift) with its interval
    spanning the fits ``fit`` gives of ``rows`` (as recorded) taken against the drift's velocity
    ``DRIFT_SIGMAS`` standard errors either side (unchanged without an interval or an error)."""
    if joint is None or joint.ci_low is None or joint.ci_high is None:
        return joint
    dv = DRIFT_SIGMAS * motion.velocity_sigma
    if dv <= 0.0:
        return joint
    velocities = (motion.velocity - dv, motion.velocity + dv)
    return spanning(joint, [fit(still_rows(rows, times, v, motion.touch)) for v in velocities])


def spanning(joint: JointFit, others: Sequence[JointFit | None]) -> JointFit:
    """``joint`` with its interval widened to hold the intervals of ``others`` (those with one)."""
    if joint.ci_low is None or joint.ci_high is None:
        return joint
    lows, highs = [joint.ci_low], [joint.ci_high]
    for other in others:
        if other is not None and other.ci_low is not None and other.ci_high is not None:
            lows.append(other.ci_low)
            highs.append(other.ci_high)
    return dataclasses.replace(joint, ci_low=min(lows), ci_high=max(highs))


def record_heart(
    rows: Sequence[Row],
    tip_forces: Sequence[float | None] | None,
    times: Sequence[float] | None,
    pulses: Sequence[float] | None,
) -> Heartbeat | None:
    """The heart's beat in a record (``estimation.pose.heartbeat``) from the ticks (s) whose
    frames carried an ECG's R-wave pulse; None without them, a tip grating or the rows' times."""
    if not pulses or times is None or not tip_forces or len(tip_forces) != len(rows):
        return None
    found = free_loads(rows, tip_forces)
    if found is None:
        return None
    states, load, sigma = found
    contact = np.isin(states, HEART_ROWS) & (load > LEVEL_SIGMAS[0] * sigma)
    advance = [r[1] for r in rows]
    return heartbeat(advance, load, times, r_waves(times, pulses), contact)


def free_loads(
    rows: Sequence[Row], tip_forces: Sequence[float | None]
) -> tuple[np.ndarray, np.ndarray, float] | None:
    """The rows' states, their tip loads above the approach's zero (N; NaN where unread) and
    the load's noise (N); None where the approach has too few rows for the zero."""
    states = np.asarray([r[0] for r in rows])
    load = np.asarray([np.nan if f is None else f for f in tip_forces], dtype=np.float64)
    free = free_load(states, load)
    if free is None:
        return None
    zero, sigma = free
    return states, load - zero, sigma


def beating_rows(rows: Sequence[Row], times: Sequence[float], heart: Heartbeat) -> list[Row]:
    """The rows with the stage's advance taken against the beating surface: as if it stood at
    the beat's mean."""
    lift = heart.lift(times)
    return [(s, u + float(h), e) for (s, u, e), h in zip(rows, lift, strict=True)]


def fitted_heart(heart: Heartbeat, fit: Callable[[Heartbeat], JointFit | None]) -> Heartbeat:
    """``heart`` at the amplitude where the residual of ``fit`` (the record's joint fit taken
    against a beat) is least, searched over ``HEART_SCALES`` of the least squares' amplitude; its
    standard error from the residual's curvature there (:func:`least_residual`), ``HEART_FLOOR``
    of it at least. Unchanged where every fit fails; not ``fixed`` where the least lies at the
    search's edge."""
    least = least_residual(
        lambda k: fit(heart.scaled(k)), HEART_SCALES, 0.01, HEART_STEP, HEART_EDGE
    )
    best, floor = least.best, HEART_FLOOR * heart.amplitude * least.best
    if not least.found:
        return heart
    if least.edge:
        return dataclasses.replace(heart.scaled(best, floor), fixed=False)
    if math.isnan(least.sigma):
        return heart.scaled(best, floor)
    return heart.scaled(best, max(least.sigma, HEART_FLOOR * best) * heart.amplitude)


@dataclass(frozen=True)
class Least:
    """Where a residual is least (:func:`least_residual`): the value, whether any fit
    succeeded, whether it lies at the search's edge, its standard error (NaN at the edge or
    where no curvature shows) and the fit there (None where none)."""

    best: float
    found: bool
    edge: bool
    sigma: float
    joint: JointFit | None


def least_residual(
    fit: Callable[[float], JointFit | None],
    bounds: tuple[float, float],
    xatol: float,
    step: float,
    edge: float,
) -> Least:
    """The value in ``bounds`` (to ``xatol``) where the squared rms residual of ``fit`` is least;
    its standard error from the residual's curvature ``step`` either side (the residuals'
    correlation counted as the fit counts it, by its noise scale: chi^2 = n rms^2 rises 1).
    A least within ``edge`` of the bounds is not a minimum (the residual still falls past it)."""
    fits: dict[float, JointFit | None] = {}  # the search's, read again at its best

    def score(x: float) -> float:
        joint = fits[x] = fit(x)
        if joint is None or not joint.success or joint.rms is None:
            return math.inf
        return float(joint.rms) ** 2

    lo, hi = bounds
    with warnings.catch_warnings():  # a failed fit scores inf: the search steps around it
        warnings.simplefilter("ignore", RuntimeWarning)
        found = minimize_scalar(score, bounds=bounds, method="bounded", options={"xatol": xatol})
    best = float(found.x)
    if not math.isfinite(found.fun):
        return Least(best, False, False, math.nan, None)
    if min(best - lo, hi - best) < edge:
        return Least(best, True, True, math.nan, None)
    joint = fits[best] if best in fits else fit(best)
    around = [score(best - step), float(found.fun), score(best + step)]
    curve = (around[0] - 2.0 * around[1] + around[2]) / step**2
    if not (math.isfinite(curve) and curve > 0) or joint is None:
        return Least(best, True, False, math.nan, joint)
    widen = joint.noise_scale or 1.0
    return Least(
        best, True, False, widen * math.sqrt(2.0 / (max(joint.n_points, 1) * curve)), joint
    )


def heart_envelope(
    joint: JointFit | None, heart: Heartbeat, fit: Callable[[Heartbeat], JointFit | None]
) -> JointFit | None:
    """``joint`` with its interval spanning the fits ``fit`` gives of the record taken against
    ``heart`` at ``DRIFT_SIGMAS`` standard errors of its amplitude either side (``fit`` measures
    the drift again at each, as the amplitude's search did: the two move together)."""
    if joint is None or joint.ci_low is None or joint.ci_high is None or heart.amplitude <= 0:
        return joint
    sigmas = (-DRIFT_SIGMAS, DRIFT_SIGMAS)
    factors = [max(0.0, 1.0 + k * heart.sigma / heart.amplitude) for k in sigmas]
    return spanning(joint, [fit(heart.scaled(f)) for f in factors])


def unfixed(
    joint: JointFit | None, heart: Heartbeat | None, beating: bool = False
) -> JointFit | None:
    """``joint`` failed where the record did not fix the heart's amplitude (``fixed``: its
    residual least at the search's edge), where the record taken against the beat still
    leaves residuals correlated to the cap (``MAX_RHO``: the beat's model does not describe
    it), or where the beat read far deeper than the indentation (``MAX_BEAT_OVER_DEPTH``): its
    modulus would be the model's, not the tissue's (on fresh scenes of docs/invivo.md, two in
    three such estimates missed the truth by 30 % or their interval missed it). With
    ``beating`` (the record holds an ECG's R waves) and no beat measured (``heart`` None: too
    few rows in contact), the beat is in the record and not taken out: it fails too."""
    if joint is None:
        return joint
    if heart is None:
        if not (beating and joint.success):
            return joint
        why = (
            "the ECG's R waves are on the record, but its contact is too short to measure the beat"
        )
    elif not heart.fixed:
        why = (
            f"the record does not fix the beat's amplitude (its fit is best at the search's "
            f"edge, {2e3 * heart.amplitude:.2f} mm peak to peak)"
        )
    elif joint.success and joint.rho >= MAX_RHO:
        why = (
            f"the record taken against the beat ({2e3 * heart.amplitude:.2f} mm peak to peak) "
            f"still misses it (residuals correlated, lag-1 {joint.rho:.2f})"
        )
    elif (depth := joint.max_depth) is not None and 2.0 * heart.amplitude > (
        MAX_BEAT_OVER_DEPTH * depth
    ):
        why = (
            f"the beat read {2e3 * heart.amplitude:.2f} mm peak to peak, over "
            f"{MAX_BEAT_OVER_DEPTH:g} times the record's {1e3 * depth:.2f} mm of indentation: "
            "the fit traded the beat's amplitude for the modulus"
        )
    else:
        return joint
    return JointFit(
        False,
        f"heartbeat: {why}; a record of a few beats, the beam buckled by the systole",
        n_points=joint.n_points,
    )


def steady_rows(
    rows: list[Row],
    times: Sequence[float] | None,
    tip_forces: Sequence[float | None] | None,
    beat: Heartbeat | None,
    drift: bool,
) -> tuple[list[Row], Motion | None]:
    """The rows taken against ``beat`` (where given) and then (with ``drift``) against the drift
    measured on them between touch and release; the motion as measured after the beat."""
    still = rows if beat is None or times is None else beating_rows(rows, times, beat)
    motion = record_motion(still, tip_forces, times)
    if motion is not None and times is not None and drift:
        still = still_rows(still, times, motion.velocity, motion.touch)
    return still, motion


def beat_fit(
    rows: list[Row],
    times: Sequence[float] | None,
    tip_forces: Sequence[float | None] | None,
    drift: bool,
    fit: JointOf,
) -> Callable[[Heartbeat], JointFit | None]:
    """The joint fit ``fit`` of ``rows`` taken against a beat (:func:`steady_rows`: the drift
    measured again after it): what the amplitude's search and its interval both read."""
    return lambda beat: fit(steady_rows(rows, times, tip_forces, beat, drift)[0])


def measured_heart(
    rows: list[Row],
    times: Sequence[float] | None,
    tip_forces: Sequence[float | None] | None,
    pulses: Sequence[float] | None,
    drift: bool,
    fit: JointOf,
) -> Heartbeat | None:
    """The heart's beat in the record (:func:`record_heart`), its amplitude where the joint fit
    ``fit`` of the rows taken against it (:func:`steady_rows`: with ``drift``, the drift measured
    again after it) is least (:func:`fitted_heart`); None without one."""
    heart = record_heart(rows, tip_forces, times, pulses)
    if heart is None:
        return None
    return fitted_heart(heart, beat_fit(rows, times, tip_forces, drift, fit))


def motion_envelope(
    joint: JointFit | None,
    raw: list[Row],
    times: Sequence[float] | None,
    tip_forces: Sequence[float | None] | None,
    found: tuple[Motion | None, Heartbeat | None],
    drift: bool,
    fit: JointOf,
) -> JointFit | None:
    """``joint`` (the fit of :func:`steady_rows`' rows of ``raw``) with its interval spanning
    the fits at the drift's velocity ``DRIFT_SIGMAS`` standard errors either side (the beat
    taken out as found) and at the beat's amplitude as many either side (the drift measured
    again at each). ``found``: the motion :func:`steady_rows` and the beat :func:`measured_heart`
    gave."""
    motion, heart = found
    if times is None:
        return joint
    if drift and motion is not None:
        beating = raw if heart is None else beating_rows(raw, times, heart)
        joint = drift_envelope(joint, beating, times, motion, fit)
    if heart is not None:
        joint = heart_envelope(joint, heart, beat_fit(raw, times, tip_forces, drift, fit))
    return joint
