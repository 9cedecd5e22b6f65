"""The exact layer law as the estimator evaluates it: solved once on a grid, then interpolated.

``estimation.contact.layer_exact`` solves the contact of a rigid sphere on a layer over a rigid
base in
linear elasticity. A fit evaluates the law at ~10^5 depths, so here it is tabulated, per layer
kind (Poisson's ratio, bonded or sliding; cached for the process and in the user's cache,
``store.cache``, so a campaign's workers do not solve them again), in two parts:

- the paraboloid's bracket ``B_p(chi) = F / F_Hertz`` at ``chi = sqrt(R delta)/h``, one curve
  (:func:`paraboloid_bracket`, chi up to 3 and beyond);
- the sphere at depth: ``T = F / (F_Sneddon(delta) B_p(a_S/h))``, with ``a_S`` Sneddon's
  half-space contact radius at the same depth, on rows of ``lambda = h/R`` (:func:`sphere_rows`).
  The composition ``F_Sneddon x B_p(a_S/h)`` alone is exact to first order in a/h (the layer's
  first effect is a uniform approach proportional to the load) and errs by up to 7 % at depth
  on thin layers (R/h = 2, delta/R = 0.6); ``T`` carries the rest, a smooth factor between 0.9
  and 1 that interpolates well across rows.

A law of given (nu, base, h/R) then gets its own factor ``G(chi) = F / F_Sneddon`` on a uniform
grid of chi (:func:`layer_factor`), and a depth costs one linear interpolation. Within the
trusted domain (chi <= CHI_MAX, delta/R <= DEPTH_RATIO_MAX) the interpolated law is within
1e-4 of a direct solve (tests); past it the factor is continued linearly and the estimator
warns (``estimation.contact.law.validity_warnings``).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import CubicSpline  # type: ignore[import-untyped,unused-ignore]

from ...store.cache import cached_arrays
from .layer_exact import kernel_transform, solve_contact
from .sneddon import sneddon_bracket, sneddon_y

FloatArray = NDArray[np.float64]

CHI_MAX = 3.0
"""Trusted layer ratio sqrt(R delta)/h of the exact law (its tables reach it for every nu)."""
DEPTH_RATIO_MAX = 1.0
"""Trusted sphere depth delta/R of the exact law's tables."""
ROW_DEPTH_RATIO = 1.6
"""The sphere's rows reach past DEPTH_RATIO_MAX, so that a law between two rows interpolates
(never clamps) up to its own reach."""
ALPHA_CAP = 7.5
"""Largest contact radius a/h solved (chi reaches 3.2-4 there, nu = 0.5 bonded the least)."""
PARABOLOID_RADII = 300
ROW_THICKNESS = np.geomspace(0.02, 20.0, 31)
"""The sphere's rows, lambda = h/R: below the first, delta/R <= 0.0036 in the domain (T = 1 to
1e-4); above the last, chi <= 0.05 (T = 1 to 1e-4); the row there is used."""
ROW_RADII = 48
ROW_POINTS = 41
FACTOR_POINTS = 257
TABLE_VERSION = 1
"""Bump it whenever a change to the layer solve (``estimation.contact.layer_exact``) or to these
tables
changes any number: the user's cache (``store.cache``) then solves them again."""


def _sneddon_radius(depth_ratio: FloatArray) -> FloatArray:
    """a/R of Sneddon's sphere on a half-space at delta/R: tanh y with y tanh y = delta/R."""
    return np.asarray(np.tanh(sneddon_y(depth_ratio)))


def _sneddon_force(depth_ratio: FloatArray) -> FloatArray:
    """F / (E* R^2) of Sneddon's sphere on a half-space at delta/R."""
    y = sneddon_y(depth_ratio)
    return np.asarray(sneddon_bracket(y, np.tanh(y)))


def _kind(poisson: float, bonded: bool) -> tuple[float, bool]:
    """The cache key of a layer kind: a sliding layer's law does not depend on nu."""
    return (round(float(poisson), 12) if bonded else 0.0), bool(bonded)


def _record(poisson: float, bonded: bool, *grid: object) -> str:
    """What a cached table was solved for: the kind, the grid, the tables' version."""
    return repr((TABLE_VERSION, poisson, bonded, *grid))


@functools.lru_cache(maxsize=64)
def _paraboloid(poisson: float, bonded: bool) -> tuple[CubicSpline, float]:
    def solve() -> dict[str, FloatArray]:
        alpha = np.linspace(ALPHA_CAP / PARABOLOID_RADII, ALPHA_CAP, PARABOLOID_RADII)
        c = solve_contact(alpha, math.inf, kernel_transform(poisson, bonded))
        return {"chi": np.sqrt(c.depth), "bracket": c.force / (4.0 / 3.0 * c.depth**1.5)}

    record = _record(poisson, bonded, ALPHA_CAP, PARABOLOID_RADII)
    solved = cached_arrays("layer-paraboloid", record, solve)
    chi, bracket = solved["chi"], solved["bracket"]
    spline = CubicSpline(np.concatenate(([0.0], chi)), np.concatenate(([1.0], bracket)))
    return spline, float(chi[-1])


def paraboloid_bracket(poisson: float, bonded: bool) -> tuple[CubicSpline, float]:
    """B_p(chi) = F/F_Hertz of a paraboloid on the layer, as a spline in chi = sqrt(R delta)/h,
    and the largest chi it was solved to."""
    return _paraboloid(*_kind(poisson, bonded))


@dataclass(frozen=True, eq=False)
class SphereRows:
    """T on rows of lambda = h/R (``thickness``), each at ``ROW_POINTS`` chi from 0 to the row's
    ``reach`` (chi_hi: CHI_MAX, DEPTH_RATIO_MAX or what the solve reached, whichever is least)."""

    thickness: FloatArray
    reach: FloatArray
    ratio: FloatArray


def _row(lam: float, poisson: float, bonded: bool) -> tuple[float, FloatArray]:
    rho = 1.0 / lam
    top = min(ALPHA_CAP, 0.99 * rho)
    alpha = np.linspace(top / ROW_RADII, top, ROW_RADII)
    c = solve_contact(alpha, rho, kernel_transform(poisson, bonded))
    chi = np.sqrt(c.depth)
    depth_ratio = c.depth * lam * lam
    bp, _ = paraboloid_bracket(poisson, bonded)
    composed = _sneddon_force(depth_ratio) * bp(_sneddon_radius(depth_ratio) / lam)
    ratio = c.force * lam**3 / composed
    reach = min(CHI_MAX * 1.2, math.sqrt(ROW_DEPTH_RATIO) / lam, float(chi[-1]))
    spline = CubicSpline(np.concatenate(([0.0], chi)), np.concatenate(([1.0], ratio)))
    return reach, np.asarray(spline(np.linspace(0.0, reach, ROW_POINTS)))


@functools.lru_cache(maxsize=64)
def _rows(poisson: float, bonded: bool) -> SphereRows:
    def solve() -> dict[str, FloatArray]:
        rows = [_row(float(lam), poisson, bonded) for lam in ROW_THICKNESS]
        return {"reach": np.array([r for r, _ in rows]), "ratio": np.array([t for _, t in rows])}

    grid = (ALPHA_CAP, PARABOLOID_RADII, ROW_THICKNESS.tolist(), ROW_RADII, ROW_POINTS)
    solved = cached_arrays("layer-sphere-rows", _record(poisson, bonded, *grid), solve)
    return SphereRows(ROW_THICKNESS, solved["reach"], solved["ratio"])


def sphere_rows(poisson: float, bonded: bool) -> SphereRows:
    """The sphere's correction T per row (cached per layer kind; ~0.2 s to build)."""
    return _rows(*_kind(poisson, bonded))


def _row_ratio(rows: SphereRows, i: int, chi: FloatArray) -> FloatArray:
    v = np.clip(chi / rows.reach[i], 0.0, 1.0) * (ROW_POINTS - 1)
    return np.asarray(np.interp(v, np.arange(ROW_POINTS), rows.ratio[i]))


def _sphere_ratio(rows: SphereRows, lam: float, chi: FloatArray) -> FloatArray:
    """T at chi for lambda = h/R: quadratic (Lagrange) in log(lambda) through the three nearest
    rows (clamped at the ends)."""
    logs = np.log(rows.thickness)
    x = float(np.clip(math.log(lam), logs[0], logs[-1]))
    i = int(np.clip(np.argmin(np.abs(logs - x)), 1, logs.size - 2))
    out = np.zeros_like(chi)
    for j in (i - 1, i, i + 1):
        weight = math.prod((x - logs[k]) / (logs[j] - logs[k]) for k in (i - 1, i, i + 1) if k != j)
        out += weight * _row_ratio(rows, j, chi)
    return out


@dataclass(frozen=True, eq=False)
class LayerFactor:
    """G(chi) = F/F_half-space of one law on a uniform grid ``step`` apart up to ``reach``."""

    step: float
    values: FloatArray
    reach: float

    def at(self, chi: FloatArray) -> tuple[FloatArray, FloatArray]:
        """G and dG/dchi at ``chi`` >= 0: linear interpolation, continued past the grid with
        its last slope."""
        x = chi / self.step
        i = np.minimum(x.astype(np.int64), self.values.size - 2)
        lo = self.values[i]
        slope = self.values[i + 1] - lo
        return lo + (x - i) * slope, slope / self.step


@functools.lru_cache(maxsize=4096)
def _factor(poisson: float, bonded: bool, lam: float, sphere: bool) -> LayerFactor:
    bp, solved = paraboloid_bracket(poisson, bonded)
    if not sphere:
        reach = min(CHI_MAX, solved)
        chi = np.linspace(0.0, reach, FACTOR_POINTS)
        return LayerFactor(float(chi[1]), np.asarray(bp(chi)), reach)
    rows = sphere_rows(poisson, bonded)
    reach = min(CHI_MAX, math.sqrt(DEPTH_RATIO_MAX) / lam, solved)
    chi = np.linspace(0.0, reach, FACTOR_POINTS)
    depth_ratio = (chi * lam) ** 2
    values = bp(_sneddon_radius(depth_ratio) / lam) * _sphere_ratio(rows, lam, chi)
    return LayerFactor(float(chi[1]), np.asarray(values), reach)


def layer_factor(poisson: float, bonded: bool, thickness_ratio: float, sphere: bool) -> LayerFactor:
    """The exact layer factor of a law with h/R = ``thickness_ratio``: against Sneddon's sphere
    on a half-space (``sphere``) or against Hertz (the paraboloid's bracket)."""
    nu, b = _kind(poisson, bonded)
    lam = float(thickness_ratio) if sphere else 1.0
    return _factor(nu, b, round(lam, 12), sphere)
