"""Sneddon's rigid sphere on a linear-elastic half-space (Sneddon 1965, Int. J. Eng. Sci.
3:47-57): with the contact radius ``a`` and ``y = artanh(a/R)``, ``delta = R y tanh(y)`` and
``F = E* R^2 [(1 + tanh(y)^2) y - tanh(y)]``. The root ``y`` of a depth and the bracket, each
vectorised and as a scalar twin: the estimator's laws (``estimation.contact.law``,
``estimation.contact.layer_table``) and the simulator's closed form (``sim.tissue``) share them."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

_SNEDDON_MAXITER = 60  # the scalar twin's guarded Newton
_SNEDDON_NEWTON_STEPS = 3  # the vectorised solve's fixed steps (see sneddon_y)
_TINY = float(np.finfo(np.float64).tiny)


def sneddon_bracket(y: FloatArray, t: FloatArray) -> FloatArray:
    """(1 + tanh^2 y) y - tanh y = (y - tanh y) + y tanh^2 y (so F = E* R^2 times this), with a
    series for y - tanh y below y = 0.05 (the direct difference loses 3 eps / y^2 relative; the
    series' truncation error is below 1e-15 there)."""
    y2 = y * y
    series = (
        y * y2 * (1 / 3 - y2 * (2 / 15 - y2 * (17 / 315 - y2 * (62 / 2835 - y2 * 1382 / 155925))))
    )
    return np.where(y < 0.05, series, y - t) + y * t * t


def sneddon_bracket_at(y: float, t: float) -> float:
    """Scalar twin of :func:`sneddon_bracket` (plain floats)."""
    if y < 0.05:
        y2 = y * y
        series = (
            y
            * y2
            * (1 / 3 - y2 * (2 / 15 - y2 * (17 / 315 - y2 * (62 / 2835 - y2 * 1382 / 155925))))
        )
        return series + y * t * t
    return y - t + y * t * t


def sneddon_y(d_over_r: FloatArray) -> FloatArray:
    """Solve y tanh(y) = d for y >= 0, element-wise (d <= 0 gives 0).

    Why this shape: the joint fit solves it for ~150k depths per trial, so it is three plain
    Newton steps from a close start, with no branch, mask or convergence test (the guarded
    iteration it replaced took 4-6 steps of several np.where's; on 4k-15k depths, the joint
    fit's block size, this is 2-4x cheaper per depth).

    Start: y^2 = d u with u = y coth y, and ``u ~ d + 1/(1 + 2/3 d + 16/45 d^2)``, which has
    u's series 1 + d/3 + 4/45 d^2 at d -> 0 and u -> d (y -> d) as d -> inf; it is within
    3.2 % of the root in y for every d >= 0 (worst near d = 1.86; checked on 2e6 roots). Newton
    squares the error (worst case 3.2e-2 -> 1.2e-4 -> 1.6e-9 -> rounding): three steps land
    within 1 ulp of the exact root, as the guarded iteration did (checked against 40-digit
    mpmath roots for 6e4 d in [1e-12, 1e3]; the tests hold it within 2 ulp of the scalar twin
    and y tanh y = d to rounding). The start is taken at min(d, 1e150) so that d u cannot
    overflow (beyond, the first step lands on y = d, exact there). The ``tiny`` in Newton's
    denominator only turns d = 0's 0/0 into y = 0: for any d > 0 the denominator is >= 2 sqrt(d)
    > 4e-162, so adding 2.2e-308 does not change its rounding.
    """
    d = np.maximum(d_over_r, 0.0)
    ds = np.minimum(d, 1e150)
    y = np.sqrt(ds * (ds + 1.0 / (1.0 + ds * (2.0 / 3.0 + ds * (16.0 / 45.0)))))
    for _ in range(_SNEDDON_NEWTON_STEPS):
        t = np.tanh(y)
        y -= (y * t - d) / (t + y * (1.0 - t * t) + _TINY)
    return y


def sneddon_y_at(d: float) -> float:
    """Scalar twin of :func:`sneddon_y`: the same root to an ulp, by a guarded Newton iteration
    (the simulator's per-position contact path calls it; its last bits are the simulated
    campaign's, so it keeps the iteration it was recorded with)."""
    y = math.sqrt(d) if d < 1.0 else d / math.tanh(d)
    lo = 0.0
    for _ in range(_SNEDDON_MAXITER):
        t = math.tanh(y)
        g = y * t - d
        if g < 0:
            lo = y
        new = y - g / (t + y * (1.0 - t * t))
        if new <= lo:
            new = 0.5 * (lo + y)
        if abs(new - y) <= 1e-15 * y:
            return new
        y = new
    return y
