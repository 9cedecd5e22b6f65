"""The inclusion's extent: a disc seen through the tip's contact, fitted to the probes.

The map's region above its threshold (``region``) is a level set of the *apparent* map: the tip
reads the tissue through a contact of radius a (1.8 mm for the paper's tip on the map scene's
phantom), so the map is the inclusion blurred by the contact, and the level half-way to the
peak lies inside the footprint of a small buried inclusion (2.2-2.4 mm for the shipped 2.5 mm
sphere: a boundary sensitivity of 0.85). The extent model undoes the contact's blur: each
probe's log E is

    log E_i = b + A * w_i(c, r),   w_i = the share of the tip's contact pressure that lies over a
                                    disc of radius r about c

with the contact's pressure Hertz's, ``p ~ sqrt(1 - rho^2/a^2)``, on the probe's own contact
radius (``Probe.contact_radius``; the probes' median where one lacks it). b and A are linear
(weighted least squares at each (c, r), A >= 0), the centre c and radius r are searched
(Nelder-Mead from the map's region), and their 95 % intervals come from the Gauss-Newton
curvature of the weighted misfit scaled by its own residual variance.

What it leaves out: the inclusion's shape below the surface. The tip's stress spreads with
depth, so a small buried sphere is felt from further away than its footprint and the disc comes
out wider (+0.6 mm for the shipped 2.5 mm sphere 1 mm under the surface, the same at 3, 5 and
10x; +1.0 mm for the lung map's 5 mm nodule under a 10 mm tip), while a large sphere is felt by
its cap, narrower than its equator (-0.3 mm at 4 mm): docs/maps.md. The map's half-peak region
errs inward on the small ones; ``region`` reports the radius's interval over both::

    ext = fit_extent(probes, start=(x, y), radius=r0)
    ext.centre, ext.radius, ext.radius_se
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import minimize  # type: ignore[import-untyped,unused-ignore]

from .probes import MM, Probe

FloatArray = NDArray[np.float64]
RADIAL_NODES = 12  # Gauss-Legendre nodes across the contact's radius
ANGLES = 24  # points around it
EDGE_WIDTH = 0.02  # the disc's edge, as a fraction of the contact radius (a smooth step)
MIN_PROBES = 6  # the fit has four parameters besides the two linear ones


class ExtentError(ValueError):
    """The probes cannot carry the extent's fit (too few, no contact radius, no rise)."""


@dataclass(frozen=True)
class Extent:
    """The fitted disc (m): centre, radius, their standard errors, the rise A on log E."""

    centre: tuple[float, float]
    radius: float
    centre_se: tuple[float, float]
    radius_se: float
    rise: float

    def as_dict(self) -> dict[str, object]:
        return {
            "center_mm": [self.centre[0] / MM, self.centre[1] / MM],
            "center_se_mm": [self.centre_se[0] / MM, self.centre_se[1] / MM],
            "radius_mm": self.radius / MM,
            "radius_se_mm": self.radius_se / MM,
            "rise": self.rise,
        }


@functools.lru_cache(maxsize=8)
def contact_points(radius: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Points (x, y, m) over a contact of ``radius`` and their weights: Hertz's pressure,
    summing to one."""
    g, w = np.polynomial.legendre.leggauss(RADIAL_NODES)
    rho = radius * 0.5 * (g + 1.0)
    theta = np.linspace(0.0, 2.0 * math.pi, ANGLES, endpoint=False)
    weight = radius * 0.5 * w * rho * np.sqrt(np.maximum(1.0 - (rho / radius) ** 2, 0.0))
    x = np.outer(rho, np.cos(theta)).ravel()
    y = np.outer(rho, np.sin(theta)).ravel()
    weights = np.repeat(weight, ANGLES)
    return x, y, weights / weights.sum()


def overlap(
    px: FloatArray, py: FloatArray, a: FloatArray, centre: tuple[float, float], r: float
) -> FloatArray:
    """w_i: the share of probe i's contact pressure (contact radius a_i, at px_i, py_i) over
    the disc of radius ``r`` about ``centre`` (all m); the disc's edge a smooth step
    EDGE_WIDTH a_i wide."""
    ux, uy, uw = contact_points(1.0)
    x = px[:, None] + a[:, None] * ux[None, :] - centre[0]
    y = py[:, None] + a[:, None] * uy[None, :] - centre[1]
    step = 0.5 * (1.0 + np.tanh((r - np.hypot(x, y)) / (EDGE_WIDTH * a[:, None])))
    return np.asarray(step @ uw)


@dataclass(frozen=True)
class _Data:
    px: FloatArray
    py: FloatArray
    a: FloatArray
    y: FloatArray  # log E
    w: FloatArray  # 1 / sigma^2

    @classmethod
    def of(cls, probes: Sequence[Probe]) -> _Data:
        used = [p for p in probes if p.usable and p.modulus is not None]
        radii = [p.contact_radius for p in used if p.contact_radius]
        if len(used) < MIN_PROBES or not radii:
            raise ExtentError(
                f"the extent needs {MIN_PROBES} probes with a number and a contact radius"
            )
        typical = float(np.median(radii))
        return cls(
            np.array([p.x for p in used]),
            np.array([p.y for p in used]),
            np.array([p.contact_radius or typical for p in used]),
            np.log([p.modulus for p in used if p.modulus is not None]),
            np.array([p.log_sigma() ** -2 for p in used]),
        )

    def linear(self, theta: FloatArray) -> tuple[float, FloatArray, FloatArray]:
        """The weighted misfit at (cx, cy, r) with b and A profiled out, the design and the
        coefficients (b, A)."""
        share = overlap(self.px, self.py, self.a, (theta[0], theta[1]), theta[2])
        design = np.stack([np.ones_like(share), share], axis=1)
        root = np.sqrt(self.w)
        coef = np.asarray(
            np.linalg.lstsq(design * root[:, None], self.y * root, rcond=None)[0], dtype=np.float64
        )
        if coef[1] < 0.0:  # a dip is no inclusion: the disc carries no rise
            coef = np.array([np.average(self.y, weights=self.w), 0.0])
        r = self.y - design @ coef
        return float(np.sum(self.w * r * r)), design, coef


def fit_extent(probes: Sequence[Probe], start: tuple[float, float], radius: float) -> Extent:
    """The disc that best explains ``probes`` (see the module docstring), searched from the
    centre ``start`` and ``radius`` (m) of the map's region.

    Raises:
        ExtentError: too few probes with a contact radius, or no rise over the background.
    """
    data = _Data.of(probes)
    scale = float(np.median(data.a))  # search in units of the contact radius

    def misfit(u: FloatArray) -> float:
        if u[2] <= 0.05:
            return math.inf
        return data.linear(u * scale)[0]

    u0 = np.array([start[0], start[1], max(radius, 0.1 * scale)]) / scale
    res = minimize(misfit, u0, method="Nelder-Mead", options={"xatol": 1e-3, "fatol": 1e-6})
    theta = np.asarray(res.x, dtype=np.float64) * scale
    rss, _, coef = data.linear(theta)
    if not (math.isfinite(rss) and coef[1] > 0.0):
        raise ExtentError("the probes show no rise a disc explains")
    se = _standard_errors(data, theta, coef, rss)
    centre = (float(theta[0]), float(theta[1]))
    return Extent(centre, float(theta[2]), (se[0], se[1]), se[2], float(coef[1]))


def _standard_errors(data: _Data, theta: FloatArray, coef: FloatArray, rss: float) -> FloatArray:
    """Gauss-Newton standard errors of (cx, cy, r) with b and A free, the misfit's own
    residual variance as the scale (at least one: the probes' intervals are not shrunk)."""
    step = 1e-3 * float(np.median(data.a))

    def model(t: FloatArray) -> FloatArray:
        share = overlap(data.px, data.py, data.a, (t[0], t[1]), t[2])
        return np.asarray(coef[0] + coef[1] * share)

    base = model(theta)
    cols = [(model(theta + step * e) - base) / step for e in np.eye(3)]
    share = (base - coef[0]) / coef[1]
    jac = np.column_stack([*cols, np.ones_like(base), share])
    dof = max(base.size - jac.shape[1], 1)
    s2 = max(rss / dof, 1.0)
    info = jac.T @ (jac * data.w[:, None])
    try:
        cov = np.linalg.inv(info) * s2
    except np.linalg.LinAlgError:
        return np.full(3, math.inf)
    return np.sqrt(np.maximum(np.diag(cov)[:3], 0.0))
