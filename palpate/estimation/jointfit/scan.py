"""Step 1 of the joint fit: scan the contact position x0 over the whole record.

The search window is the whole record: from ``search`` before its first stage position (the
record may start in contact) to its deepest ``depth_base`` (contact at the very end). A first
guess (``estimation.detect.contact``) only adds a grid point: a late or missing guess cannot
confine the fit. E and P0 are linear, so at each x0 of a grid at most SCAN_STEP apart (at
least SCAN_POINTS, at most MAX_SCAN_POINTS points) they have a closed form
(``grid.grid_fits``, weights 1/sigma_P^2): the global basin without local-minimum trouble. The
best grid point starts the refinement (step 2, ``refine``).

Cost: one grid of law evaluations, 121-601 rows x N (a 5 mm record: 251 rows).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..belief import Hypothesis
from .grid import grid_fits
from .record import Record
from .result import FitFailed

FloatArray = NDArray[np.float64]

SCAN_POINTS = 121
MAX_SCAN_POINTS = 601
SCAN_STEP = 20e-6  # m: finer than the refinement needs to land in the global basin


@dataclass(frozen=True, eq=False)
class Start:
    """Where the refinement starts.

    Attributes:
        lo, hi: the search window of x0 (m); the refinement stays inside it.
        compliance: c (m/N) of the hypothesis scanned (the depth is ``depth_base - c P - x0``).
        theta: (3,) log E, x0 and P0 / p_scale at the scan's best point; (2,) without P0.
        p_scale: P0's unit in ``theta`` (N): the median sigma_P, so every parameter is O(1).
        load_offset: whether P0 is fitted (``theta`` carries it).
    """

    lo: float
    hi: float
    compliance: float
    theta: FloatArray
    p_scale: float
    load_offset: bool


def scan(
    hypothesis: Hypothesis,
    record: Record,
    contact_guess: float | None,
    search: float,
    load_offset: bool,
) -> Start:
    """The best x0 of ``hypothesis`` on a grid over the whole record: from ``search`` (m) below
    the first advance to the deepest ``depth_base`` (``contact_guess``, m, is one more point).

    Raises:
        ValueError: a non-finite ``contact_guess``.
        FitFailed: the window is empty, or no x0 in it gives a positive load.
    """
    if contact_guess is not None and not math.isfinite(contact_guess):
        raise ValueError(f"contact_guess must be finite, got {contact_guess!r}")
    c = hypothesis.compliance
    depth_base = record.depth_base_at(c)
    lo = float(record.advance.min()) - search
    hi = float(depth_base.max())
    if not hi > lo:
        raise FitFailed("no contact: the record ends before the contact search window")
    points = min(max(math.ceil((hi - lo) / SCAN_STEP) + 1, SCAN_POINTS), MAX_SCAN_POINTS)
    grid = np.linspace(lo, hi, points)
    if contact_guess is not None and lo < contact_guess < hi:
        grid = np.sort(np.append(grid, contact_guess))
    w0 = 1.0 / record.sigma_force**2
    [(E_grid, P0_grid, rss_grid, S_grid)] = grid_fits(
        [hypothesis.law], depth_base, record.force, w0, grid, load_offset
    )
    usable = (S_grid > 0) & (E_grid > 0)
    if not np.any(usable):
        raise FitFailed("no contact: no contact position in the window gives a positive load")
    k = int(np.argmin(np.where(usable, rss_grid, np.inf)))
    p_scale = float(np.median(record.sigma_force))
    theta0 = np.array([math.log(E_grid[k]), grid[k], P0_grid[k] / p_scale])
    if not load_offset:
        theta0 = theta0[:2]
    return Start(lo, hi, c, theta0, p_scale, load_offset)
