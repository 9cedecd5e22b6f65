"""Step 3b of the joint fit: the intervals of E and x0 by profile likelihood over x0 and the
belief's open properties.

With the weights frozen at the solution (``noise``), for each candidate (a hypothesis of the
belief, ``estimation.belief``, in one model form) and each x0 on a fine grid, E has a closed form
Ê(x0) (P0 profiled out too), the weighted residual RSS(x0) and curvature S(x0) (the Schur
complement of the (E, P0) normal matrix; ``grid.closed_form``). A *family* is the candidates of
one model form. Each candidate's region ``RSS + S (E - Ê)^2 <= RSS_min + threshold``, with
RSS_min *that candidate's* minimum over x0, is the profile over x0 and the load offset; the
family's interval of E is the union of its candidates' regions projected on E, and of x0 on
x0. The record is not let choose between the belief's values (a thickness, a Poisson ratio, a
compliance within the stated ranges): the closed forms' own error can make it prefer the wrong
one by more than the noise (a neo-Hookean layer's stiffening reads as a Poisson ratio of 0.5,
docs/lung.md), so the interval holds E for every value the operator left open. The point
estimate still weighs them (``Profile.center``, the family's 50 % region over all candidates
together). The grid starts at
``x0_hat +- span`` and widens (x3) until every family's region closes inside it, or reaches the
search window's edge (then flagged).

The candidates share grids: those on the same depth base (one compliance) and Poisson ratio
share the law's half-space part (``grid.grid_fits``).

Cost: PROFILE_POINTS x N law evaluations per candidate and width tried (usually one).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..contact.law import ContactLaw
from .grid import GridFit, grid_fits

FloatArray = NDArray[np.float64]

PROFILE_POINTS = 241
PROFILE_TRIES = 6  # grid widths tried per profile (x3 each) before calling it open at the edge
CENTER_LEVEL = 0.454936  # chi^2(1) median: the 50 % profile interval's RSS level (in s^2)


@dataclass(frozen=True)
class Candidate:
    """One law on one depth base: ``base`` indexes the depth bases (one per compliance),
    ``family`` the model form it belongs to."""

    law: ContactLaw
    base: int
    family: int


@dataclass(frozen=True)
class Profile:
    """One family's profile: its best E on the grid (Pa), the interval of E (Pa) and of x0 (m),
    whether the region reached the search window's edge or stayed open, the best point: its
    candidate (index), contact position x0 (m) and load offset P0 (N); and ``center``, the
    middle (geometric) of the family's 50 % profile interval of E: the point estimate when
    the belief leaves properties open (see ``envelope``)."""

    modulus: float
    ci_low: float
    ci_high: float
    contact_low: float
    contact_high: float
    edge: bool
    best: int = 0
    best_contact: float = 0.0
    best_offset: float = 0.0
    center: float = 0.0


def profiles(
    laws: Sequence[ContactLaw],
    depth_base: FloatArray,
    P: FloatArray,
    w: FloatArray,
    x0_hat: float,
    span: float,
    threshold: float,
    lo: float,
    hi: float,
    offset: bool,
) -> list[Profile | None]:
    """Each law's own profile (each law its own family, one depth base): see
    :func:`family_profiles`."""
    candidates = [Candidate(law, 0, i) for i, law in enumerate(laws)]
    return family_profiles(
        candidates, [(depth_base, w)], P, x0_hat, span, threshold, (lo, hi), offset
    )


def family_profiles(
    candidates: Sequence[Candidate],
    bases: Sequence[tuple[FloatArray, FloatArray]],
    P: FloatArray,
    x0_hat: float,
    span: float,
    threshold: float,
    window: tuple[float, float],
    offset: bool,
    scale2: float = 1.0,
) -> list[Profile | None]:
    """Each family's profile (None: no candidate and contact position gives a positive load),
    families numbered 0.. by ``Candidate.family``. The grid, centred on ``x0_hat`` (m), widens
    until every family's region closes (at most PROFILE_TRIES - 1 times, x3 each; still open
    then: reported as reaching the edge). ``bases``: per compliance, the (N,) depth base
    (``record.Record.depth_base_at``) and the frozen weights at that compliance (the effective
    variance depends on it, ``noise.weights_at``); ``P``: (N,) loads; ``threshold``: on the
    RSS (``noise.Noise``);
    ``window``: the search window (lo, hi) of x0 (m); ``offset``: P0 is fitted; ``scale2``:
    s^2 of the noise model (the marginal's weights)."""
    lo, hi = window
    families = sorted({c.family for c in candidates})
    found: list[Profile | None] = []
    for attempt in range(PROFILE_TRIES):
        a, b = max(lo, x0_hat - span), min(hi, x0_hat + span)
        grid = np.linspace(a, b, PROFILE_POINTS)
        fits = _candidate_fits(candidates, bases, P, grid, offset)
        found, still_open = [], False
        for fam in families:
            members = [i for i, c in enumerate(candidates) if c.family == fam]
            prof, open_grid = read_family(
                fits, members, grid, (threshold, scale2), a <= lo, b >= hi
            )
            found.append(prof)
            still_open |= open_grid
        if not still_open or attempt == PROFILE_TRIES - 1:
            break
        span *= 3.0
    return found


def _candidate_fits(
    candidates: Sequence[Candidate],
    bases: Sequence[tuple[FloatArray, FloatArray]],
    P: FloatArray,
    grid: FloatArray,
    offset: bool,
) -> list[GridFit]:
    """Every candidate's grid fit; candidates on one depth base with one Poisson ratio go in
    one :func:`grid_fits` call (they share the half-space part)."""
    groups: dict[int, list[int]] = {}
    for i, c in enumerate(candidates):
        groups.setdefault(c.base, []).append(i)
    fits: list[GridFit | None] = [None] * len(candidates)
    for base, idx in groups.items():
        laws = [candidates[i].law for i in idx]
        depth_base, w = bases[base]
        for i, fit in zip(idx, grid_fits(laws, depth_base, P, w, grid, offset), strict=True):
            fits[i] = fit
    return [fit for fit in fits if fit is not None]


def read_family(
    fits: Sequence[GridFit],
    members: Sequence[int],
    grid: FloatArray,
    noise: tuple[float, float],
    at_low_end: bool,
    at_high_end: bool,
) -> tuple[Profile | None, bool]:
    """One family's profile on one grid: (its intervals, whether its region is open at a grid end
    that is not the search window's, i.e. the grid should widen). ``fits`` are every
    candidate's, ``members`` the family's indices into them; ``noise``: (threshold, s^2);
    ``at_low_end``/``at_high_end``: the grid's first/last point is the search window's edge."""
    threshold, scale2 = noise
    indices = [i for i in members if np.any(fits[i][3] > 0)]
    usable = [fits[i] for i in indices]
    if not usable:
        return None, False
    masked = [np.where(S > 0, rss, np.inf) for _, _, rss, S in usable]
    j = min(range(len(usable)), key=lambda m: float(np.min(masked[m])))
    best_k = int(np.argmin(masked[j]))
    best = float(masked[j][best_k])
    lo, hi, first, last = _union(usable, [float(np.min(m)) + threshold for m in masked])
    c_lo, c_hi, _, _ = _projection(usable, best + CENTER_LEVEL * scale2)
    window_edge = (first == 0 and at_low_end) or (last == grid.size - 1 and at_high_end)
    open_grid = (first == 0 or last == grid.size - 1) and not window_edge
    E_best, P0_best = usable[j][0][best_k], usable[j][1][best_k]
    profile = Profile(
        modulus=float(E_best),
        ci_low=lo,
        ci_high=hi,
        contact_low=float(grid[first]),
        contact_high=float(grid[last]),
        edge=window_edge or open_grid,
        best=indices[j],
        best_contact=float(grid[best_k]),
        best_offset=float(P0_best),
        center=float(np.sqrt(c_lo * c_hi)) if c_lo > 0 else float(E_best),
    )
    return profile, open_grid


def _union(fits: Sequence[GridFit], levels: Sequence[float]) -> tuple[float, float, int, int]:
    """The union of each fit's region ``RSS + S (E - Ê)^2 <= level`` at its own level,
    projected on E (lo, hi, Pa) and on the grid (first and last index inside)."""
    parts = [_projection([fit], level) for fit, level in zip(fits, levels, strict=True)]
    return (
        min(p[0] for p in parts),
        max(p[1] for p in parts),
        min(p[2] for p in parts),
        max(p[3] for p in parts),
    )


def _projection(fits: Sequence[GridFit], level: float) -> tuple[float, float, int, int]:
    """The region RSS + S (E - Ê)^2 <= ``level`` of every fit in ``fits`` (one grid) projected
    on E (lo, hi, Pa) and on the grid (first and last index inside)."""
    lows, highs, first, last = [], [], -1, -1
    for E, _, rss, S in fits:
        idx = np.nonzero((S > 0) & (rss <= level))[0]
        if idx.size == 0:
            continue
        h = np.sqrt(np.maximum(level - rss[idx], 0.0) / S[idx])
        lows.append(float(np.min(E[idx] - h)))
        highs.append(float(np.max(E[idx] + h)))
        first = int(idx[0]) if first < 0 else min(first, int(idx[0]))
        last = max(last, int(idx[-1]))
    return min(lows), max(highs), first, last
