"""The stiffness map: a Gaussian process of log E over the patch, each probe with its own noise.

Why scikit-learn's ``GaussianProcessRegressor``: it takes a per-point noise variance
(``alpha``), which is what a probe's interval is (heteroscedastic), fits the kernel's amplitude
and length scale by maximum marginal likelihood with restarts, and returns the posterior mean,
sd and covariance; a hand-written GP would repeat it. The process is on log E (moduli are
positive and their intervals scale with them), its mean the probes' median over the area
they cover (:func:`area_median`; the background tissue: an inclusion fills a small part of a
patch), coordinates in mm (the length scale's
bound: about a tip radius, the narrowest bump a tip sees). Usage::

    m = StiffnessMap.fit(probes, patch)
    mean, sd = m.predict(points_m)          # log E and its sd at (M, 2) points (m)
    m.background                            # log E of the tissue around the inclusion
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from sklearn.exceptions import ConvergenceWarning
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.gaussian_process.kernels import RBF, ConstantKernel

from .probes import Probe

FloatArray = NDArray[np.float64]
MM = 1e-3
# the kernel's length scale (mm): from a tenth of a millimetre up to LENGTH_SCALE_MAX, the width
# of the narrowest bump the map must not miss (a tip sees an inclusion over about its own radius:
# 3.6 mm fitted on a dense raster over the shipped scene's 5 mm inclusion under the 3.5 mm tip);
# a longer scale would let a flat map claim a certainty between probes it has not earned
LENGTH_SCALE_MIN_MM = 0.1
LENGTH_SCALE_MAX = 4e-3  # m, the default (a survey passes 1.2 tip radii)
# the kernel's variance on log E: at least 0.01 (an unprobed point may be 10 % off the
# background), at most 4 (a factor of 7)
AMPLITUDE = (0.01, 4.0)
MIN_PROBES = 3  # a map needs this many usable probes


@dataclass(frozen=True)
class Patch:
    """The rectangle a map covers (m): ``x_min, y_min, x_max, y_max``."""

    x_min: float
    y_min: float
    x_max: float
    y_max: float

    def __post_init__(self) -> None:
        if not (self.x_max > self.x_min and self.y_max > self.y_min):
            raise ValueError(f"a patch needs x_max > x_min and y_max > y_min, got {self}")

    @classmethod
    def from_mm(cls, corners: tuple[float, float, float, float]) -> Patch:
        x0, y0, x1, y1 = corners
        return cls(x0 * MM, y0 * MM, x1 * MM, y1 * MM)

    @property
    def diagonal(self) -> float:
        return math.hypot(self.x_max - self.x_min, self.y_max - self.y_min)

    @property
    def area(self) -> float:
        return (self.x_max - self.x_min) * (self.y_max - self.y_min)

    def grid(self, n: int) -> tuple[FloatArray, FloatArray]:
        """An n x n grid of points over the patch, edges included: x (n,), y (n,)."""
        return np.linspace(self.x_min, self.x_max, n), np.linspace(self.y_min, self.y_max, n)

    def points(self, n: int) -> FloatArray:
        """The n x n grid as (n * n, 2) points, x fastest."""
        x, y = self.grid(n)
        xx, yy = np.meshgrid(x, y)
        return np.column_stack([xx.ravel(), yy.ravel()])


class MapError(ValueError):
    """Too few usable probes for a map."""


def area_median(xy: FloatArray, values: FloatArray, n: int = 41) -> float:
    """The median of ``values`` over the area the probes at ``xy`` cover (each weighted by the
    share of an n x n grid over their bounding box nearest to it): an active plan crowds its
    probes on the inclusions, and their plain median reads the tissue around them high (369
    kPa against 319 on a 314 kPa phantom holding two). A raster's probes weigh the same.

    >>> corners = [[0, 0], [0, 1], [1, 0], [1, 1]]
    >>> crowd = [[0.9, 0.9], [0.95, 0.9], [0.9, 0.95], [0.95, 0.95], [0.92, 0.92]]
    >>> values = np.array([1.0] * 4 + [2.0] * 5)
    >>> float(np.median(values)), area_median(np.array(corners + crowd), values)
    (2.0, 1.0)
    """
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    gx, gy = (np.linspace(a, b, n) for a, b in zip(lo, hi, strict=True))
    cells = np.stack([g.ravel() for g in np.meshgrid(gx, gy)], axis=1)
    nearest = np.argmin(((cells[:, None, :] - xy[None, :, :]) ** 2).sum(axis=2), axis=1)
    weight = np.bincount(nearest, minlength=len(values)).astype(float)
    order = np.argsort(values)
    cumulative = np.cumsum(weight[order])
    return float(values[order][np.searchsorted(cumulative, 0.5 * cumulative[-1])])


@dataclass(frozen=True)
class StiffnessMap:
    """A fitted map (:meth:`fit`): the process, the probes it used, the background log E."""

    gp: GaussianProcessRegressor
    used: tuple[Probe, ...]
    left_out: tuple[tuple[Probe, str], ...]
    background: float

    @classmethod
    def fit(
        cls, probes: list[Probe], *, seed: int = 0, length_scale_max: float = LENGTH_SCALE_MAX
    ) -> StiffnessMap:
        """The map of ``probes`` (those without a usable number left out with their reason),
        its length scale at most ``length_scale_max`` (m).

        Raises:
            MapError: fewer than :data:`MIN_PROBES` usable probes.
        """
        used = tuple(p for p in probes if p.usable)
        left = tuple((p, str(p.why_left_out())) for p in probes if not p.usable)
        if len(used) < MIN_PROBES:
            raise MapError(f"{len(used)} usable probes; a map needs {MIN_PROBES}")
        xy = np.array([[p.x / MM, p.y / MM] for p in used])
        y = np.log([float(p.modulus or 0.0) for p in used])
        noise = np.array([p.log_sigma() ** 2 for p in used])
        background = area_median(xy, y)
        top = length_scale_max / MM
        kernel = ConstantKernel(0.01, AMPLITUDE) * RBF(0.5 * top, (LENGTH_SCALE_MIN_MM, top))
        gp = GaussianProcessRegressor(
            kernel, alpha=noise, n_restarts_optimizer=2, random_state=seed, normalize_y=False
        )
        with warnings.catch_warnings():  # a bound reached is a fact of the data, not a fault
            warnings.simplefilter("ignore", ConvergenceWarning)
            gp.fit(xy, y - background)
        return cls(gp, used, left, background)

    def predict(self, points: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Posterior mean and sd of log E at ``points`` (M, 2) in m."""
        mean, sd = self.gp.predict(np.asarray(points) / MM, return_std=True)
        return np.asarray(mean) + self.background, np.asarray(sd)

    def draws(self, points: FloatArray, n: int, rng: np.random.Generator) -> FloatArray:
        """``n`` joint posterior draws of log E at ``points`` (M, 2): (n, M)."""
        mean, cov = self.gp.predict(np.asarray(points) / MM, return_cov=True)
        m = cov.shape[0]
        chol = np.linalg.cholesky(cov + 1e-10 * np.eye(m))
        return np.asarray(mean + self.background + rng.standard_normal((n, m)) @ chol.T)

    @property
    def length_scale(self) -> float:
        """The fitted length scale (m)."""
        return float(self.gp.kernel_.k2.length_scale) * MM
