"""Step 3b of the joint fit: the intervals of E and x0 by profile likelihood over x0.

With the weights frozen at the solution (``noise``), for each x0 on a fine grid E has a closed
form Ê(x0) (P0 profiled out too), the weighted residual RSS(x0) and curvature S(x0) (the Schur
complement of the (E, P0) normal matrix; ``grid.closed_form``). The region
``RSS(x0) + S(x0) (E - Ê(x0))^2 <= RSS_min + threshold`` projected on E is E's interval, and
projected on x0 the contact interval. The grid starts at ``x0_hat +- span`` and widens (x3) until
the region closes inside it, or reaches the search window's edge (then flagged).

Every model form (step 4, ``envelope``) is profiled here with the same weights; the forms go in
lockstep on the same grids so they share the law's half-space part (``grid.grid_fits``).

Cost: PROFILE_POINTS x N law evaluations per width tried (usually one), shared by the forms.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from estimation.corrections import ContactLaw
from estimation.jointfit.grid import GridFit, grid_fits

FloatArray = NDArray[np.float64]

PROFILE_POINTS = 241
PROFILE_TRIES = 6  # grid widths tried per profile (x3 each) before calling it open at the edge


@dataclass(frozen=True)
class Profile:
    """One model form's profile: its best E on the grid (Pa), the interval of E (Pa) and of
    x0 (m), and whether the region reached the search window's edge or stayed open."""

    modulus: float
    ci_low: float
    ci_high: float
    contact_low: float
    contact_high: float
    edge: bool


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
    """Each law's E and x0 intervals from its profile over x0 (None: no contact position gives
    a positive load). A law's grid, centred on ``x0_hat``, widens until its region closes (at
    most PROFILE_TRIES - 1 times, x3 each; still open then: reported as reaching the edge). The
    minimum is searched on the grid, so a law need not be the one that was fitted (the other
    model forms are profiled with the same weights ``w``). ``depth_base``, ``P``, ``w``: (N,)
    as in :func:`grid_fits`; ``threshold``: on the RSS (``noise.Noise``); [lo, hi]: the search
    window (m); ``offset``: P0 is fitted.

    The laws go in lockstep: at each width, every law still open is evaluated on the same grid,
    so they share the half-space part (:func:`grid_fits`); each law sees the same grids, hence
    the same result, as if profiled alone."""
    done: dict[int, Profile | None] = {}
    pending = list(range(len(laws)))
    for attempt in range(PROFILE_TRIES):
        a, b = max(lo, x0_hat - span), min(hi, x0_hat + span)
        grid = np.linspace(a, b, PROFILE_POINTS)
        fits = grid_fits([laws[i] for i in pending], depth_base, P, w, grid, offset)
        still_open = []
        for i, fit in zip(pending, fits, strict=True):
            profile, open_grid = read_profile(fit, grid, threshold, a <= lo, b >= hi)
            if open_grid and attempt < PROFILE_TRIES - 1:
                still_open.append(i)
            else:
                done[i] = profile
        if not still_open:
            break
        pending = still_open
        span *= 3.0
    return [done[i] for i in range(len(laws))]


def read_profile(
    fit: GridFit, grid: FloatArray, threshold: float, at_low_end: bool, at_high_end: bool
) -> tuple[Profile | None, bool]:
    """The profile on one grid: (its intervals, whether the region is open at a grid end that
    is not the search window's, i.e. the grid should widen). ``at_low_end``/``at_high_end``:
    the grid's first/last point is the search window's edge."""
    E, _, rss, S = fit
    ok = S > 0
    if not np.any(ok):
        return None, False
    best = float(np.min(rss[ok]))
    inside = ok & (rss <= best + threshold)
    idx = np.nonzero(inside)[0]
    window_edge = bool((inside[0] and at_low_end) or (inside[-1] and at_high_end))
    open_grid = bool(inside[0] or inside[-1]) and not window_edge
    h = np.sqrt(np.maximum(best + threshold - rss[idx], 0.0) / S[idx])
    profile = Profile(
        modulus=float(E[ok][np.argmin(rss[ok])]),
        ci_low=float(np.min(E[idx] - h)),
        ci_high=float(np.max(E[idx] + h)),
        contact_low=float(grid[idx[0]]),
        contact_high=float(grid[idx[-1]]),
        edge=window_edge or open_grid,
    )
    return profile, open_grid
