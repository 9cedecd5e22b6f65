"""Least-squares beam state from G >= 2 measured grating strains: :func:`fit_strains` and its parts.

The model (:class:`StrainModel`) gives the grating-mean strains against z = sqrt(e_g / L), in
which they are nearly linear (they grow like sqrt(e_g) at onset), for either buckling direction;
its ``fit`` scans z over the branch and refines it. :func:`straight_fit` is the alternative, the
straight (pre-buckling) beam, which :func:`fit_strains` returns when it fits as well.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..beam.elastica import fast
from ..beam.elastica._scipy import least_squares
from ..beam.elastica.constants import E_OVER_L_MAX
from ..beam.model import Beam

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class StrainFit:
    """Least-squares beam state from grating strains (see :func:`fit_strains`).

    Attributes:
        e: total end shortening (m).
        P: axial load (N).
        e_geometric: elastica (inextensible) part of e (m); 0 if not buckled.
        residual: rms of model minus measured strain over the gratings (strain units).
        direction: +1 if the strains fit the model's buckling direction, -1 its mirror image.
        buckled: False if the best fit has no bending (then P and e are only bounded).
        success, message: solver status and what the numbers mean.
    """

    e: float
    P: float
    e_geometric: float
    residual: float
    direction: int
    buckled: bool
    success: bool
    message: str


def checked_strains(
    strains: ArrayLike, sigma: ArrayLike | None, shape: tuple[int, ...]
) -> tuple[FloatArray, FloatArray]:
    """The (G,) measured strains and their weights 1/sigma (ones without sigma), for intervals
    of ``shape`` (G,); ValueError for a shape mismatch, G < 2, or a non-finite or bad value."""
    y = np.asarray(strains, dtype=float)
    if y.shape != shape or y.size < 2:
        raise ValueError(
            f"strains must have shape (G,) with G >= 2 matching intervals {shape}, got {y.shape}"
        )
    if not np.all(np.isfinite(y)):
        raise ValueError("strains must be finite")
    if sigma is None:
        return y, np.ones_like(y)
    sig = np.broadcast_to(np.asarray(sigma, dtype=float), y.shape)
    if not np.all(np.isfinite(sig) & (sig > 0.0)):
        raise ValueError("sigma must be finite and > 0")
    return y, 1.0 / sig


@dataclass(frozen=True, eq=False)
class StrainModel:
    """The grating strains of :func:`fit_strains`'s model against the amplitude z = sqrt(e_g/L)
    and the buckling direction: arcs ``s0``, ``s1`` (G,) as fractions of L; with
    ``include_axial`` the uniform -P/EA as well."""

    beam: Beam
    s0: FloatArray
    s1: FloatArray
    include_axial: bool

    def __call__(self, z: FloatArray, direction: int) -> FloatArray:
        """(K, G) strains at K amplitudes ``z`` (K,), mirrored when ``direction`` is -1."""
        g = np.minimum(z * z, E_OVER_L_MAX)
        strain = direction * self.beam.mean_bending(g[:, None], self.s0, self.s1)
        if self.include_axial:
            strain = strain - self.beam.slenderness_ratio * fast.load(g)[:, None]
        return np.asarray(strain)

    def fit(
        self, y: FloatArray, weight: FloatArray, grid: int, xtol: float, max_nfev: int
    ) -> tuple[int, Any]:
        """(direction, scipy's OptimizeResult for z): a scan of ``grid`` values of z over the
        branch in both directions picks the basin, least squares refines z within the
        neighbouring grid cells (residuals scaled to O(1), so the tolerances mean what they say).
        """
        z_grid = np.linspace(0.0, math.sqrt(E_OVER_L_MAX), grid)
        costs = [np.sum((weight * (self(z_grid, d) - y)) ** 2, axis=1) for d in (1, -1)]
        d_index, i_best = np.unravel_index(int(np.argmin(np.stack(costs))), (2, grid))
        direction, i = (1, -1)[int(d_index)], int(i_best)
        lo, hi = z_grid[max(i - 1, 0)], z_grid[min(i + 1, grid - 1)]
        scale = float(np.max(np.abs(weight * y))) or 1.0
        fit = least_squares(
            lambda z: weight * (self(z, direction)[0] - y) / scale,
            np.array([z_grid[i]]),
            bounds=(lo, hi),
            method="trf",
            xtol=xtol,
            ftol=xtol,
            gtol=xtol,
            max_nfev=max_nfev,
        )
        return direction, fit


def straight_fit(
    beam: Beam, y: FloatArray, weight: FloatArray, include_axial: bool
) -> tuple[StrainFit, float]:
    """The best straight-beam (pre-buckling) state and its weighted squared residual."""
    e_cr = beam.critical_shortening()
    if include_axial:
        w2 = weight**2
        eps = float(np.clip(-np.sum(w2 * y) / np.sum(w2), 0.0, e_cr / beam.length))
        fit = StrainFit(
            e=eps * beam.length,
            P=beam.EA * eps,
            e_geometric=0.0,
            residual=float(np.sqrt(np.mean((y + eps) ** 2))),
            direction=1,
            buckled=False,
            success=True,
            message="not buckled: e fitted from the uniform axial strain -e/L",
        )
        return fit, float(np.sum((weight * (y + eps)) ** 2))
    fit = StrainFit(
        e=e_cr,
        P=beam.critical_load(),
        e_geometric=0.0,
        residual=float(np.sqrt(np.mean(y**2))),
        direction=1,
        buckled=False,
        success=True,
        message=(
            "no bending in the strains: the beam is straight (before or at buckling), so P is "
            "only bounded, 0 <= P <= P_cr; returning the onset state P = P_cr, "
            "e = P_cr L / EA (upper bounds)"
        ),
    )
    return fit, float(np.sum((weight * y) ** 2))


def fit_strains(
    beam: Beam,
    strains: ArrayLike,
    intervals: ArrayLike,
    sigma: ArrayLike | None = None,
    *,
    include_axial: bool = False,
    grid: int = 256,
    xtol: float = 1e-15,
    max_nfev: int = 200,
) -> StrainFit:
    """Least-squares beam state from G >= 2 measured grating-mean strains (paper: G = 3).

    Args:
        strains: (G,) measured mean strains, either sign (see the module note on signs).
        intervals: (G, 2) grating arcs as in ``grating_strains``.
        sigma: None, a scalar or (G,) standard deviations (> 0) weighting the residuals.
        include_axial: model the uniform -P/EA as well (use it if the data contain it).
        grid, xtol, max_nfev: scan size and the refinement's tolerance and budget.

    Method: the unknown is z = sqrt(e_g / L), in which the bending strains are nearly
    linear (they grow like sqrt(e_g) at onset), so the fit is well conditioned down to
    onset. A scan of ``grid`` values of z over the branch, for both buckling directions,
    picks the global basin; ``least_squares`` then refines z within the neighbouring grid
    cells. If the best fit has no bending (e.g. all-zero strains), the beam is straight and
    the strains cannot give P below P_cr: without ``include_axial`` we return the onset
    state (P = P_cr, e = P_cr L / EA), an upper bound, and say so in ``message``; with it,
    e is fitted from the uniform strain -e/L.
    """
    s0, s1 = beam.intervals(intervals)
    y, weight = checked_strains(strains, sigma, s0.shape)
    if beam.fiber_offset == 0.0:
        raise ValueError("fiber_offset is 0: the fiber sees no bending strain, nothing to fit")
    model = StrainModel(beam, s0, s1, include_axial)
    direction, fit = model.fit(y, weight, grid, xtol, max_nfev)
    z = float(fit.x[0])
    misfit = model(np.array([z]), direction)[0] - y
    straight, straight_cost = straight_fit(beam, y, weight, include_axial)
    if straight_cost <= float(np.sum((weight * misfit) ** 2)) * (1.0 + 1e-9):
        return straight
    g = min(z * z, E_OVER_L_MAX)
    p = float(fast.load(np.array(g)))
    return StrainFit(
        e=(g + beam.slenderness_ratio * p) * beam.length,
        P=p * beam.load_unit,
        e_geometric=g * beam.length,
        residual=float(np.sqrt(np.mean(misfit**2))),
        direction=direction,
        buckled=True,
        success=bool(fit.success),
        message=f"buckled (first mode): {fit.message}",
    )
