"""The relaxation fit's numerics: the spectrum's fixed times, the memory basis, one contact
position's non-negative least squares, and the intervals (``estimation.relaxation``)."""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import nnls  # type: ignore[import-untyped,unused-ignore]

from ..contact.law import ContactLaw
from ..jointfit.noise import lag1
from .result import RelaxationRecord

FloatArray = NDArray[np.float64]

PER_DECADE = 4  # spectrum times per decade
TAIL = 3.0  # the slowest time: this many times the record's span in contact


@dataclass(frozen=True)
class Solved:
    """One contact position's fit: weighted RSS, coefficients (E_inf, c_k), the weighted design
    and residuals."""

    rss: float
    coef: FloatArray  # (1 + K,): E_inf, c_k
    design: FloatArray  # weighted (N, 1 + K), the offset projected out
    residual: FloatArray  # weighted
    in_contact: NDArray[np.bool_]  # (N,): delta > 0
    last: FloatArray  # (1 + K,): the unweighted design's last row (f, h_k at the end)


def still_relaxing(solved: Solved) -> float:
    """The fraction of the fitted load at the record's last sample that is still relaxing
    (the memory terms' share): what the relaxed modulus would lose if it all relaxed."""
    last = solved.last * solved.coef
    total = float(last.sum())
    return float(last[1:].sum()) / total if total > 0 else 0.0


def scale2(solved: Solved, n: int) -> float:
    """The noise's inflation: the reduced chi^2 (when above 1) times the effective-sample-size
    factor (1 + rho)/(1 - rho) of the residuals' lag-1 autocorrelation in contact."""
    dof = max(n - 1 - int(np.count_nonzero(solved.coef[1:])), 1)
    rho = lag1(solved.residual[solved.in_contact])
    return max(1.0, solved.rss / dof) * (1.0 + rho) / (1.0 - rho)


def span_in_contact(record: RelaxationRecord, x0: float) -> float:
    inside = record.times[record.depth_base > x0]
    return float(inside[-1] - inside[0]) if inside.size > 1 else 0.0


def spectrum(record: RelaxationRecord, depth: float, x0: float) -> FloatArray:
    """The spectrum's fixed times (s): four a decade from twice the median tick to ``TAIL``
    times the span in contact (empty when the record is not in contact for two ticks)."""
    if depth <= 0:
        return np.zeros(0)
    dt = float(np.median(np.diff(record.times)))
    span = span_in_contact(record, x0)
    lo, hi = 2.0 * dt, TAIL * span
    if hi <= lo:
        return np.zeros(0)
    n = max(math.ceil(math.log10(hi / lo) * PER_DECADE) + 1, 2)
    return np.geomspace(lo, hi, n)


SCAN_EXPONENT = 600.0  # exp(600) < 1e308: the longest stretch of exp(t/tau) a scan holds


def memory_basis(times: FloatArray, shape: FloatArray, taus: FloatArray) -> FloatArray:
    """h_k(t_i) (N, K): the exact recursion of a piecewise-linear ``shape`` in time (the
    module docstring), at rest before ``times[0]``: ``h_i = exp(-dt_i/tau) h_(i-1) +
    (1 - exp(-dt_i/tau))/(dt_i/tau) df_i``. A record's steps come in runs of one length (its
    ticks, then its averaged blocks); within a run of step dt the recursion is the scan
    ``h_(i0+r) = a^(r+1) h_(i0-1) + a^r sum_(s<=r) a^(-s) g df_(i0+s)``, a = exp(-dt/tau),
    every time at once, cut where a^(-s) would overflow. Before the shape first moves it is 0.
    A jittered clock (runs of a few steps) is stepped a row at a time, every time at once."""
    df = np.diff(shape, prepend=0.0)
    dt = np.diff(times, prepend=times[0])
    out = np.zeros((times.size, taus.size))
    moved = np.flatnonzero(df)
    if moved.size == 0:
        return out
    first = int(moved[0])
    runs = _equal_steps(dt[first:])
    if len(runs) > max(8, (dt.size - first) // 8):
        x = dt[:, None] / taus[None, :]
        decay = np.exp(-x)
        drive = np.where(x > 0, -np.expm1(-x) / np.where(x > 0, x, 1.0), 1.0) * df[:, None]
        h = np.zeros(taus.size)
        for i in range(first, dt.size):
            h = decay[i] * h + drive[i]
            out[i] = h
        return out
    carried = np.zeros(taus.size)
    for start, stop in runs:
        rows = _scan(df[first + start : first + stop], float(dt[first + start]), taus, carried)
        out[first + start : first + stop] = rows
        carried = rows[-1]
    return out


def _equal_steps(dt: FloatArray) -> list[tuple[int, int]]:
    """[start, stop) runs of equal steps (to 1e-6); the first step is a run of its own (the
    record's first sample has none)."""
    if dt.size <= 2:
        return [(i, i + 1) for i in range(dt.size)]
    cut = np.flatnonzero(~np.isclose(dt[2:], dt[1:-1], rtol=1e-6, atol=0.0)) + 2
    edges = [0, 1, *cut.tolist(), dt.size]
    return list(itertools.pairwise(edges))


def _scan(df: FloatArray, step: float, taus: FloatArray, before: FloatArray) -> FloatArray:
    """The recursion over a run of equal steps ``step`` (s), every time at once, from the
    state ``before`` (K,); in stretches short enough that exp(s step/tau) stays finite."""
    x = step / taus
    gain = -np.expm1(-x) / x if step > 0 else np.ones_like(taus)
    length = max(1, int(SCAN_EXPONENT / float(np.max(x)))) if step > 0 else df.size
    rows = np.empty((df.size, taus.size))
    h = before
    for lo in range(0, df.size, length):
        r = np.arange(min(length, df.size - lo), dtype=np.float64)[:, None]
        grow = np.exp(r * x)  # a^(-r)
        summed = np.cumsum(df[lo : lo + r.size, None] * gain * grow, axis=0)
        rows[lo : lo + r.size] = (h * np.exp(-x) + summed) / grow
        h = rows[lo + r.size - 1]
    return rows


def solve(
    record: RelaxationRecord, law: ContactLaw, x0: float, modulus: float, taus: FloatArray
) -> Solved:
    f, df = law.shape(record.depth_base - x0)
    var = record.sigma_load**2 + (modulus * df * record.sigma_depth) ** 2
    w = 1.0 / np.sqrt(var)
    columns = [f[:, None]]
    if taus.size:
        columns.append(memory_basis(record.times, f, taus))
    raw = np.hstack(columns)
    design, target = _offset_free(raw * w[:, None], record.load * w, w)
    scale = np.maximum(np.linalg.norm(design, axis=0), 1e-300)
    coef, _ = nnls(design / scale, target, maxiter=50 * design.shape[1])
    coef = coef / scale
    residual = target - design @ coef
    return Solved(float(residual @ residual), coef, design, residual, raw[:, 0] > 0, raw[-1])


def _offset_free(
    design: FloatArray, target: FloatArray, w: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """The weighted problem with a constant load offset profiled out (projected on the
    complement of the offset's weighted column ``w``): the joint fit's offset, corrected by
    whatever the relaxing record needs, as a free linear parameter of either sign."""
    unit = w / np.linalg.norm(w)
    return design - np.outer(unit, unit @ design), target - unit * (unit @ target)


def interval(
    solved: list[Solved], rss: FloatArray, scale2: float, q: float, combo: FloatArray
) -> tuple[float, float]:
    """The interval of ``combo . coef`` (E_inf or E_0): each x0's active-set standard error,
    the profile over x0 projected (module docstring)."""
    floor = float(rss.min())
    lows, highs = [], []
    for s, r in zip(solved, rss, strict=True):
        room = q - (r - floor) / scale2
        if room < 0 or s.coef[0] <= 0:
            continue
        active = np.flatnonzero(s.coef > 0)
        a = s.design[:, active]
        try:
            cov = np.linalg.inv(a.T @ a) * scale2
        except np.linalg.LinAlgError:
            continue
        g = combo[active]
        se = math.sqrt(max(float(g @ cov @ g), 0.0))
        value = float(combo @ s.coef)
        half = se * math.sqrt(room)
        lows.append(value - half)
        highs.append(value + half)
    if not lows:
        value = float(combo @ solved[int(np.argmin(rss))].coef)
        return value, value
    return max(min(lows), 0.0), max(highs)
