"""The rig's compliance, calibrated on a rigid reference (as AFM users calibrate a cantilever).

Between the stage encoder and the sensor's clamp sits whatever gives under load: the printed
tube's tip on the robot, the stage and its mount on the bench. Pressed on a rigid reference the
tissue does not indent, so every bit of stage advance past contact goes into the beam's end
shortening e (read from the strains, ``estimation.beam.states``) and the clamp's give c P::

    u - e = x0 + c P        (P > 0, in contact)

a straight line in P whose slope is the compliance c (m/N) and whose intercept is the contact
position. :func:`fit_compliance` fits it by least squares on the rising part of the record
between LOAD_WINDOW of its largest load (below, the contact's onset; above, the buckled plateau,
where the load hardly changes and the strain-inferred shortening's small errors would set the
slope). The interval is the slope's, with the residuals' scatter inflated by their lag-1
autocorrelation (an AR(1) misfit shortens the effective sample, as in
``estimation.jointfit.noise``). A stiff rig's load rises within a few samples (fewer than
MIN_POINTS): its compliance is then bounded, not resolved, by the advance the rise took (plus
one sample's step) over the load it gained: c in [0, that bound].

The estimate of every other trial then subtracts c P from the depth (``estimation.belief``);
an uncalibrated rig is profiled over a plausible range instead, and its verdict says so.

Pure functions, SI units; failure is a result with ``success`` False and a message.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from statistics import NormalDist

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..jointfit.noise import lag1

FloatArray = NDArray[np.float64]

LOAD_WINDOW = (0.2, 0.95)
MIN_POINTS = 10


@dataclass(frozen=True)
class ComplianceFit:
    """Result of :func:`fit_compliance`: c (m/N) with its interval, the contact x0 (m)."""

    success: bool
    message: str
    compliance: float | None = None
    ci_low: float | None = None
    ci_high: float | None = None
    contact: float | None = None
    n_points: int = 0
    confidence: float = 0.95

    def as_dict(self) -> dict[str, object]:
        return {
            "success": self.success,
            "message": self.message,
            "compliance": self.compliance,
            "ci_low": self.ci_low,
            "ci_high": self.ci_high,
            "contact": self.contact,
            "n_points": self.n_points,
            "confidence": self.confidence,
        }


def less(fit: ComplianceFit, compliance: float) -> ComplianceFit:
    """``fit`` with a known compliance (m/N) in series taken out of the value and its interval:
    what is left is the rest of the rig's (a tip grating's element is the sensor's own, and
    ``config.schema.StackConfig.compliance`` adds it back to every estimate)."""
    if compliance == 0.0 or fit.compliance is None:
        return fit
    shifted = [None if v is None else v - compliance for v in (fit.ci_low, fit.ci_high)]
    return dataclasses.replace(
        fit, compliance=fit.compliance - compliance, ci_low=shifted[0], ci_high=shifted[1]
    )


def fit_compliance(
    advance: ArrayLike, force: ArrayLike, shortening: ArrayLike, confidence: float = 0.95
) -> ComplianceFit:
    """The compliance from a rigid-reference record: (N,) stage positions u (m), axial loads P
    (N) and beam end shortenings e (m) (see the module docstring).

    Raises:
        ValueError: mismatched or non-finite arrays, a confidence outside (0, 1).
    """
    u, P, e = (np.asarray(a, dtype=np.float64) for a in (advance, force, shortening))
    if not (u.shape == P.shape == e.shape and u.ndim == 1):
        raise ValueError("advance, force and shortening must be (N,) arrays of one shape")
    if not np.all(np.isfinite(u) & np.isfinite(P) & np.isfinite(e)):
        raise ValueError("advance, force and shortening must be finite")
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence must be in (0, 1), got {confidence!r}")
    if u.size == 0 or not float(np.max(P)) > 0.0:
        return ComplianceFit(False, "no contact: the load never rises", confidence=confidence)
    lo, hi = LOAD_WINDOW
    top = int(np.argmax(hi * P.max() <= P))  # the rise ends where the load first reaches hi
    sel = (lo * P.max() < P) & (np.arange(P.size) < top)
    n = int(np.count_nonzero(sel))
    if n < MIN_POINTS:
        return _bounded(u, P, top, n, confidence)
    x, y = P[sel], (u - e)[sel]
    A = np.column_stack([x, np.ones(n)])
    coef, *_ = np.linalg.lstsq(A, y, rcond=None)
    r = y - A @ coef
    rho = lag1(r)
    s2 = float(r @ r) / max(n - 2, 1) * (1.0 + rho) / (1.0 - rho)
    var_c = s2 * float(np.linalg.inv(A.T @ A)[0, 0])
    half = NormalDist().inv_cdf(0.5 + 0.5 * confidence) * math.sqrt(max(var_c, 0.0))
    c = float(coef[0])
    return ComplianceFit(True, "ok", c, c - half, c + half, float(coef[1]), n, confidence)


def _bounded(u: FloatArray, P: FloatArray, top: int, n: int, confidence: float) -> ComplianceFit:
    """A stiff rig: c in [0, (advance over the rise + one step) / load gained]."""
    lo = LOAD_WINDOW[0]
    start = int(np.argmax(lo * P.max() < P))
    steps = np.diff(u)
    step = float(np.median(steps[steps > 0])) if np.any(steps > 0) else 0.0
    gained = float(P[top] - P[start])
    if top <= start or gained <= 0.0:
        msg = "no rising load in contact: the compliance is undetermined"
        return ComplianceFit(False, msg, n_points=n, confidence=confidence)
    bound = (float(u[top] - u[start]) + step) / gained
    msg = f"ok (a stiff rig: the load rose within {n} samples; the compliance is bounded)"
    return ComplianceFit(True, msg, 0.5 * bound, 0.0, bound, None, n, confidence)


def pooled(fits: Sequence[ComplianceFit]) -> tuple[float, float] | None:
    """The calibrated range (min, max) in m/N from several trials on a rigid reference: the
    envelope of their intervals, floored at 0 (None if none succeeded). The envelope, not a
    weighted mean: a tube's compliance may depend on the direction it is loaded in."""
    ok = [f for f in fits if f.success and f.ci_low is not None and f.ci_high is not None]
    if not ok:
        return None
    lo = max(0.0, min(float(f.ci_low) for f in ok if f.ci_low is not None))
    hi = max(lo, *(float(f.ci_high) for f in ok if f.ci_high is not None))
    return lo, hi
