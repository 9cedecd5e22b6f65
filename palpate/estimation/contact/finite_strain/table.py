"""The neo-Hookean departure as the estimator evaluates it: shipped rows, one factor a law.

:func:`.departure.departure_row` takes ~6 s a row, so the rows ship with the package
(``departure.npz``, written by ``python -m palpate.estimation.contact.finite_strain.generate``, ~8
min
on two cores): Poisson ratios ``POISSON``, bonded and sliding, layers ``R/h`` in
``INVERSE_THICKNESS`` (0: the half-space), each row ``ROW_POINTS`` depths to delta/h = 0.45 or
delta/R = 0.6. A law of given (nu, base, R/h, tip) gets its own curve ``D(delta/R)`` on a
uniform grid (:func:`departure_curve`) of the strain ``s = delta/R + delta/h`` (delta/h on a
thin layer, delta/R on a thick one: every row reaches s = 0.45): each row at the grid's
strains, a cubic spline across rows in R/h, then linear in nu; so a depth costs one
interpolation. Past a row's reach the curve continues at its last slope (the verdict flags the
layer's compression first: ``estimation.contact.law``).

    >>> curve = departure_curve(0.45, bonded=True, inverse_thickness=3.5 / 1.5, tip="frictionless")
    >>> curve.at(delta / R)          # (D, dD/d(delta/R))
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import CubicSpline  # type: ignore[import-untyped,unused-ignore]

FloatArray = NDArray[np.float64]
Tip = Literal["frictionless", "sticking"]
Column = Literal["frictionless", "sticking", "stick_spread"]

POISSON = (0.25, 0.35, 0.40, 0.45, 0.47, 0.49, 0.499)
INVERSE_THICKNESS = (0.0, 0.1, 0.2, 0.35, 0.5, 0.7, 1.0, 1.4, 2.0, 2.8, 4.0, 5.6, 8.0)
"""R/h of the rows: 0 is the half-space; 8 a layer an eighth of the tip's radius."""
TABLE_PATH = Path(__file__).with_name("departure.npz")
CURVE_POINTS = 181
CURVE_STRAIN = 0.9
"""The curve's grid: s = delta/R + delta/h in [0, CURVE_STRAIN], CURVE_POINTS points."""


@dataclass(frozen=True, eq=False)
class Rows:
    """The shipped rows: ``depth`` (delta/R), ``frictionless`` and ``sticking`` departures and
    the sticking one's half-spread (``stick_spread``), each (len(POISSON), 2 [bonded, sliding],
    len(INVERSE_THICKNESS), ROW_POINTS)."""

    depth: FloatArray
    frictionless: FloatArray
    sticking: FloatArray
    stick_spread: FloatArray


@functools.cache
def load_rows(path: Path = TABLE_PATH) -> Rows:
    """The shipped rows (read once a process)."""
    with np.load(path) as data:
        return Rows(data["depth"], data["frictionless"], data["sticking"], data["stick_spread"])


@dataclass(frozen=True, eq=False)
class DepartureCurve:
    """``D`` of one law on a uniform grid (``step``) of s = delta/R (1 + R/h), D(0) = 0;
    ``scale`` = 1 + R/h."""

    step: float
    values: FloatArray
    slopes: FloatArray
    scale: float

    def at(self, depth_ratio: FloatArray) -> tuple[FloatArray, FloatArray]:
        """D and dD/d(delta/R) at ``depth_ratio`` >= 0 (past the grid: continued linearly)."""
        x = np.asarray(depth_ratio, dtype=np.float64) * self.scale
        grid_top = self.step * (self.values.size - 1)
        inside = np.minimum(x, grid_top)
        d = np.interp(inside, self._grid, self.values) + (x - inside) * self.slopes[-1]
        return d, np.interp(inside, self._grid, self.slopes) * self.scale

    @functools.cached_property
    def _grid(self) -> FloatArray:
        return np.asarray(np.arange(self.values.size) * self.step, dtype=np.float64)


def _row_at(depth: FloatArray, values: FloatArray, grid: FloatArray) -> FloatArray:
    """One row at ``grid`` depths: (0, 0) prepended, linear inside, held at the last slope."""
    x = np.concatenate([[0.0], depth])
    y = np.concatenate([[0.0], values])
    slope = (y[-1] - y[-2]) / (x[-1] - x[-2])
    inside = np.interp(np.minimum(grid, x[-1]), x, y)
    return np.asarray(inside + np.maximum(grid - x[-1], 0.0) * slope)


def departure_curve(
    poisson: float, bonded: bool, inverse_thickness: float, tip: Tip
) -> DepartureCurve:
    """The departure curve of a law: Poisson ratio (clamped to the rows' POISSON range), base,
    ``inverse_thickness`` = R/h (0: half-space; past the last row, that row), the tip.

    Raises:
        ValueError: ``tip`` is not frictionless or sticking, or R/h < 0.
    """
    if tip not in ("frictionless", "sticking"):
        raise ValueError(f"tip must be 'frictionless' or 'sticking', got {tip!r}")
    return _curve(poisson, bonded, inverse_thickness, tip)


def stick_spread_curve(poisson: float, bonded: bool, inverse_thickness: float) -> DepartureCurve:
    """Half the spread of the sticking tip's two limits, as :func:`departure_curve`."""
    return _curve(poisson, bonded, inverse_thickness, "stick_spread")


@functools.lru_cache(maxsize=256)
def _curve(
    poisson: float, bonded: bool, inverse_thickness: float, column: Column
) -> DepartureCurve:
    if not inverse_thickness >= 0.0:
        raise ValueError(f"inverse_thickness must be >= 0, got {inverse_thickness!r}")
    rows = load_rows()
    grid = np.linspace(0.0, CURVE_STRAIN, CURVE_POINTS)
    table = getattr(rows, column)
    base = 0 if bonded else 1
    nus = np.asarray(POISSON)
    nu = float(np.clip(poisson, nus[0], nus[-1]))
    k = int(np.clip(np.searchsorted(nus, nu) - 1, 0, nus.size - 2))
    weight = (nu - nus[k]) / (nus[k + 1] - nus[k])
    inv = min(float(inverse_thickness), INVERSE_THICKNESS[-1])
    per_nu = []
    for j in (k, k + 1):
        across = np.array(
            [
                _row_at(rows.depth[j, base, i] * (1.0 + r), table[j, base, i], grid)
                for i, r in enumerate(INVERSE_THICKNESS)
            ]
        )
        per_nu.append(CubicSpline(np.asarray(INVERSE_THICKNESS), across, axis=0)(inv))
    values = (1.0 - weight) * per_nu[0] + weight * per_nu[1]
    slopes = np.gradient(values, grid)
    return DepartureCurve(float(grid[1]), np.asarray(values), slopes, 1.0 + inv)
