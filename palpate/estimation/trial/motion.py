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
from collections.abc import Callable, Sequence

from ..jointfit import JointFit
from ..pose.motion import Motion, surface_motion

Row = tuple[str, float, Sequence[float]]
DRIFT_SIGMAS = 3.0


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
    lows, highs = [joint.ci_low], [joint.ci_high]
    for v in (motion.velocity - dv, motion.velocity + dv):
        other = fit(still_rows(rows, times, v, motion.touch))
        if other is not None and other.ci_low is not None and other.ci_high is not None:
            lows.append(other.ci_low)
            highs.append(other.ci_high)
    return dataclasses.replace(joint, ci_low=min(lows), ci_high=max(highs))
