"""Least-squares beam state from G >= 2 measured grating strains: ``Beam.fit_strains``'s parts.

The model (:class:`StrainModel`) gives the grating-mean strains against z = sqrt(e_g / L), in
which they are nearly linear (they grow like sqrt(e_g) at onset), for either buckling direction;
its ``fit`` scans z over the branch and refines it. :func:`straight_fit` is the alternative, the
straight (pre-buckling) beam, which ``Beam.fit_strains`` returns when it fits as well.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from estimation.elastica import fast
from estimation.elastica._scipy import least_squares
from estimation.elastica.constants import E_OVER_L_MAX

if TYPE_CHECKING:
    from estimation.beam import Beam

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class StrainFit:
    """Least-squares beam state from grating strains (see ``Beam.fit_strains``).

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
    """The grating strains of ``Beam.fit_strains``'s model against the amplitude z = sqrt(e_g/L)
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
