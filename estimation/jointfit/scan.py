"""Step 1 of the joint fit: scan the contact position x0 over the search window.

E and P0 are linear, so at each x0 of a grid of SCAN_POINTS they have a closed form
(``grid.grid_fits``, weights 1/sigma_P^2): the global basin without local-minimum trouble. The
best grid point starts the refinement (step 2, ``refine``).

Cost: one SCAN_POINTS x N grid of law evaluations (the profile's is twice as fine).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from estimation.corrections import ContactLaw
from estimation.jointfit.grid import grid_fits
from estimation.jointfit.record import Record
from estimation.jointfit.result import FitFailed

FloatArray = NDArray[np.float64]

SCAN_POINTS = 121


@dataclass(frozen=True, eq=False)
class Start:
    """Where the refinement starts.

    Attributes:
        lo, hi: the search window of x0 (m); the refinement stays inside it.
        theta: (3,) log E, x0 and P0 / p_scale at the scan's best point; (2,) without P0.
        p_scale: P0's unit in ``theta`` (N): the median sigma_P, so every parameter is O(1).
        load_offset: whether P0 is fitted (``theta`` carries it).
    """

    lo: float
    hi: float
    theta: FloatArray
    p_scale: float
    load_offset: bool


def scan(
    law: ContactLaw,
    record: Record,
    contact_guess: float | None,
    search: float,
    load_offset: bool,
) -> Start:
    """The best x0 on a grid over ``contact_guess +- search`` (m), cut to the record: x0 no
    lower than ``search`` below the first advance, no higher than the deepest ``depth_base``
    (None: centred on the middle of the advance range).

    Raises:
        ValueError: a non-finite ``contact_guess``.
        FitFailed: the window is empty, or no x0 in it gives a positive load.
    """
    u = record.advance
    guess = 0.5 * (float(u.min()) + float(u.max())) if contact_guess is None else contact_guess
    if not math.isfinite(guess):
        raise ValueError(f"contact_guess must be finite, got {contact_guess!r}")
    lo = max(guess - search, float(u.min()) - search)
    hi = min(guess + search, float(record.depth_base.max()))
    if not hi > lo:
        raise FitFailed("no contact: the record ends before the contact search window")
    grid = np.linspace(lo, hi, SCAN_POINTS)
    w0 = 1.0 / record.sigma_force**2
    [(E_grid, P0_grid, rss_grid, S_grid)] = grid_fits(
        [law], record.depth_base, record.force, w0, grid, load_offset
    )
    usable = (S_grid > 0) & (E_grid > 0)
    if not np.any(usable):
        raise FitFailed("no contact: no contact position in the window gives a positive load")
    k = int(np.argmin(np.where(usable, rss_grid, np.inf)))
    p_scale = float(np.median(record.sigma_force))
    theta0 = np.array([math.log(E_grid[k]), grid[k], P0_grid[k] / p_scale])
    if not load_offset:
        theta0 = theta0[:2]
    return Start(lo, hi, theta0, p_scale, load_offset)
