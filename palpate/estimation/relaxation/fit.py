"""The relaxation fit's recipe (method: ``estimation.relaxation``)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..contact.law import ContactLaw
from ..jointfit.pooling import chi2_quantile
from .result import FloatArray, RelaxationFit, RelaxationRecord
from .spectrum import (
    Solved,
    interval,
    scale2,
    solve,
    span_in_contact,
    spectrum,
    still_relaxing,
)

X0_POINTS = 41  # the contact grid of the profile
X0_REACH = 0.25e-3  # m either side of the joint fit's contact interval
X0_MOVES = 5  # times the grid is extended past an edge where the best point sits
RELAXES_CHI2 = 25.0  # noise variances the spectrum must gain over the elastic law
RELAXES_MIN = 0.03  # and E_0 / E_inf - 1 above this, for "the record relaxes"
INCOMPLETE = 0.02  # of the last sample's load still relaxing: the relaxed modulus not reached
SPECTRUM_FORM = 0.005  # relative: a fixed spectrum's own misfit of a relaxation between its times
MIN_HOLD_POINTS = 20


@dataclass(frozen=True)
class _Profiles:
    """The contact grid and, on it, the fits with the spectrum reaching past the record
    (``tail``), cut at its span in contact (``inside``, times ``within``) and the elastic law."""

    grid: FloatArray
    tail: list[Solved]
    inside: list[Solved]
    elastic: list[Solved]
    taus: FloatArray
    within: FloatArray
    span: float


def fit_relaxation(
    record: RelaxationRecord,
    law: ContactLaw,
    contact: tuple[float, float, float],
    modulus: float,
    *,
    model_form: float = 0.0,
    confidence: float = 0.95,
) -> RelaxationFit:
    """E_inf, E_0 and the relaxation time of ``record`` with the contact law ``law`` (one
    hypothesis of the belief: ``beliefs.fit_over_beliefs`` runs each); ``contact`` the joint
    fit's (low, x0, high) (m), ``modulus`` its E (Pa, for the depth noise's weight). See
    ``estimation.relaxation``."""
    _check(record, contact, modulus, confidence)
    n = record.times.size
    if record.hold <= 0:
        return RelaxationFit(False, "no hold in the record", n_points=n)
    lo = contact[0]
    taus = spectrum(record, float(np.max(record.depth_base) - lo), lo)
    if taus.size == 0:
        return RelaxationFit(False, "too short a record in contact", n_points=n)
    p = _profiles(record, law, modulus, taus, contact)
    floor = p.tail[int(np.argmin([s.rss for s in p.tail]))]
    s2 = scale2(floor, n)
    q = chi2_quantile(confidence)
    # relaxation slower than the record: only where the record needs it (chi^2 by q)
    slow_gain = (min(s.rss for s in p.inside) - floor.rss) / s2
    complete = slow_gain <= q
    full, times = (p.inside, p.within) if complete else (p.tail, p.taus)
    best = int(np.argmin([s.rss for s in full]))
    n_contact = int(np.count_nonzero(full[best].in_contact))
    if n_contact < MIN_HOLD_POINTS or full[best].coef[0] <= 0:
        return RelaxationFit(False, f"no fit: {n_contact} samples in contact", n_points=n)
    noise = (s2, q, confidence)
    return _result(record, p, (full, times, best), noise, (complete, slow_gain), model_form)


def _result(
    record: RelaxationRecord,
    p: _Profiles,
    chosen: tuple[list[Solved], FloatArray, int],
    noise: tuple[float, float, float],
    tail: tuple[bool, float],
    model_form: float,
) -> RelaxationFit:
    """The fit at the chosen spectrum (its fits on the grid, its times, the best point): the
    moduli, their intervals, whether it relaxes and whether the relaxation is complete."""
    full, times, best = chosen
    s2, q, confidence = noise
    complete, slow_gain = tail
    rss = np.array([s.rss for s in full])
    solved = full[best]
    relaxed = interval(full, rss, s2, q, np.r_[1.0, np.zeros(times.size)])
    instant = interval(full, rss, s2, q, np.ones(1 + times.size))
    gain = (min(s.rss for s in p.elastic) - solved.rss) / s2
    e_inf, c = float(solved.coef[0]), solved.coef[1:]
    relaxes = bool(gain > RELAXES_CHI2 and e_inf + c.sum() > (1.0 + RELAXES_MIN) * e_inf)
    relaxing = still_relaxing(solved)
    complete = not relaxes or (complete and relaxing <= INCOMPLETE)
    warnings: tuple[str, ...] = ()
    if not complete:
        bounds = (e_inf * (1.0 - relaxing), e_inf / max(1.0 - relaxing, 1e-9))
        relaxed = _extrapolated(p, relaxed, (s2, q), bounds)
        warnings = (
            f"relaxation not complete within the record: {100 * relaxing:.0f} % of the load is "
            f"still relaxing at its end and relaxation slower than its {p.span:.1f} s in contact "
            f"gains delta chi^2 = {slow_gain:.0f}, so the relaxed modulus is extrapolated (a "
            "longer hold measures it)",
        )
    eps = max(model_form, 0.0) + SPECTRUM_FORM
    return RelaxationFit(
        True,
        "ok",
        relaxed=e_inf,
        relaxed_low=relaxed[0] * (1.0 - eps),
        relaxed_high=relaxed[1] * (1.0 + eps),
        instantaneous=e_inf + float(c.sum()),
        instantaneous_low=instant[0] * (1.0 - eps),
        instantaneous_high=instant[1] * (1.0 + eps),
        relaxation_time=float(c @ times / c.sum()) if relaxes and c.sum() > 0 else None,
        relaxes=relaxes,
        complete=complete,
        delta_chi2=float(gain),
        hold=record.hold,
        n_points=record.times.size,
        contact=float(p.grid[best]),
        confidence=confidence,
        warnings=warnings,
        rss=min(s.rss for s in p.tail),
        noise_scale=s2,
    )


def floor_rss(
    record: RelaxationRecord,
    law: ContactLaw,
    contact: tuple[float, float, float],
    modulus: float,
) -> float:
    """The lowest weighted RSS of ``record`` under ``law`` (the spectrum reaching past the
    record, profiled over the contact): what :attr:`RelaxationFit.rss` is, without the rest of
    the fit (the belief check's alternatives need no moduli)."""
    _check(record, contact, modulus, 0.5)
    taus = spectrum(record, float(np.max(record.depth_base) - contact[0]), contact[0])
    if taus.size == 0:
        return math.inf
    _, tail = _profile(record, law, modulus, taus, contact)
    return min(s.rss for s in tail)


def _extrapolated(
    p: _Profiles,
    relaxed: tuple[float, float],
    noise: tuple[float, float],
    bounds: tuple[float, float],
) -> tuple[float, float]:
    """The relaxed modulus's interval where the relaxation is not complete: the envelope of the
    cut and the reaching spectrum's, down to ``bounds[0]`` (Pa: as much again as the fit says is
    still relaxing relaxes) and up to ``bounds[1]`` (Pa: none of it does, the modulus the record
    ends at: a relaxation modulus only falls, so the relaxed one is no higher). A fit that
    extrapolates relaxation as slow as the hold may put the rest of it either way: on fresh
    gels relaxing over 3.5-6 s behind a 5 s hold, 4 of 48 intervals without the upper bound
    ended 1-3 % under the truth (docs/viscoelastic.md, "Fresh draws")."""
    rss = np.array([s.rss for s in p.inside])
    inner = interval(p.inside, rss, noise[0], noise[1], np.r_[1.0, np.zeros(p.within.size)])
    return min(relaxed[0], inner[0], bounds[0]), max(relaxed[1], inner[1], bounds[1])


def _profiles(
    record: RelaxationRecord,
    law: ContactLaw,
    modulus: float,
    taus: FloatArray,
    contact: tuple[float, float, float],
) -> _Profiles:
    grid, tail = _profile(record, law, modulus, taus, contact)
    span = span_in_contact(record, float(grid[int(np.argmin([s.rss for s in tail]))]))
    within = taus[taus <= span]
    inside = [solve(record, law, x, modulus, within) for x in grid]
    elastic = [solve(record, law, x, modulus, taus[:0]) for x in grid]
    return _Profiles(grid, tail, inside, elastic, taus, within, span)


def _profile(
    record: RelaxationRecord,
    law: ContactLaw,
    modulus: float,
    taus: FloatArray,
    contact: tuple[float, float, float],
) -> tuple[FloatArray, list[Solved]]:
    """x0 on a grid of ``X0_POINTS`` over the joint fit's contact interval widened by
    ``X0_REACH`` either side (an elastic fit of a relaxing record places the contact early),
    moved on while the best point is at the grid's edge (at most ``X0_MOVES`` times), then a
    finer grid around the best point."""
    lo, _, hi = contact
    reach = 0.5 * (hi - lo) + X0_REACH
    grid = np.linspace(lo - reach, hi + reach, X0_POINTS)
    solved = [solve(record, law, x, modulus, taus) for x in grid]
    for _ in range(X0_MOVES):
        best = int(np.argmin([s.rss for s in solved]))
        if 0 < best < grid.size - 1:
            break
        step = grid[1] - grid[0]
        extra = (
            grid[-1] + step * np.arange(1, 11) if best else grid[0] - step * np.arange(10, 0, -1)
        )
        more = [solve(record, law, x, modulus, taus) for x in extra]
        grid = np.concatenate([grid, extra]) if best else np.concatenate([extra, grid])
        solved = solved + more if best else more + solved
    best = int(np.argmin([s.rss for s in solved]))
    step = grid[1] - grid[0]
    fine = grid[best] + step * np.linspace(-1.0, 1.0, 11)[1:-1]
    fine = fine[~np.isin(fine, grid)]
    grid = np.concatenate([grid, fine])
    solved = solved + [solve(record, law, x, modulus, taus) for x in fine]
    order = np.argsort(grid)
    return grid[order], [solved[i] for i in order]


def _check(
    record: RelaxationRecord, contact: tuple[float, float, float], modulus: float, conf: float
) -> None:
    n = record.times.size
    arrays = (record.load, record.depth_base, record.sigma_load, record.sigma_depth)
    if any(a.shape != (n,) for a in arrays) or record.times.ndim != 1:
        raise ValueError("the relaxation record's arrays must all be (N,)")
    if not all(np.all(np.isfinite(a)) for a in (record.times, *arrays)):
        raise ValueError("the relaxation record must be finite")
    if np.any(np.diff(record.times) <= 0):
        raise ValueError("the relaxation record's times must increase")
    if np.any(record.sigma_load <= 0) or np.any(record.sigma_depth < 0):
        raise ValueError("sigma_load must be > 0 and sigma_depth >= 0")
    lo, x0, hi = contact
    if not (math.isfinite(lo) and math.isfinite(hi) and lo <= x0 <= hi):
        raise ValueError(f"contact must be (low, x0, high) in order, got {contact}")
    if not (math.isfinite(modulus) and modulus > 0 and 0.0 < conf < 1.0):
        raise ValueError("modulus must be > 0 Pa and confidence in (0, 1)")
