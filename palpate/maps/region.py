"""What a map says: the stiff region, whether it is an inclusion, where, and how large.

The threshold on log E is given, or taken from the data: half-way (in log E) between the
background and the map's peak, but never closer to the background than ``min_rise`` (10 %: more
than twice the paper sensor's scatter between repeats on one homogeneous sample), so a flat
patch has nothing above it. The region is where the process is above it with probability over
one half; an inclusion is **found** when some point of the patch is above it with probability
at least ``found_probability`` (0.95), else the summary says "no inclusion found" with its
evidence (the largest probability, the peak's rise). The centre is the region's centroid
weighted by how far the mean is above the threshold, its interval the 2.5 and 97.5
percentiles over joint posterior draws (each draw's own region and centroid). The region is
the *apparent* map's: the tip's contact blurs the inclusion, and a level set half-way to the
peak lies inside a small inclusion's footprint. So the inclusion's extent, the boundary the
summary reports, is the disc fitted through the tip's contact (``extent``) where the probes
carry their contact radii; its radius's interval spans the two forms, from the apparent
region's (the draws' 2.5 percentile, inside) to the disc's (its 97.5 %, outside); without
contact radii the region and its draws' radius are the answer, as before::

    summary = summarise(StiffnessMap.fit(probes), patch)
    summary.found, summary.centre, summary.centre_ci, summary.radius, summary.inside(x, y)
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage  # type: ignore[import-untyped,unused-ignore]
from scipy.special import ndtr  # type: ignore[import-untyped,unused-ignore]

from .depth import DepthReading
from .extent import Extent, ExtentError, fit_extent
from .gp import LENGTH_SCALE_MAX, MIN_PROBES, MM, MapError, Patch, StiffnessMap
from .probes import Z95, Probe

FloatArray = NDArray[np.float64]
MIN_RISE = 0.10  # the smallest rise above the background a threshold from the data takes
FOUND_PROBABILITY = 0.95
GRID = 41  # points a side of the summary's grid
DRAW_GRID = 25  # points a side of the posterior draws' grid
DRAWS = 200
Interval = tuple[float, float]


@dataclass(frozen=True)
class Inclusion:
    """One region the map reads as an inclusion (m, Pa).

    Attributes:
        kind: ``"stiff"`` or ``"soft"``.
        centre, centre_ci: its centre and the 95 % intervals of x and y.
        radius, radius_ci: its radius and 95 % interval.
        extreme: the map's highest (stiff) or lowest (soft) modulus in it.
        probability: how sure the map is that its most certain point is past the level.
        depth: its sphere read from the probes about it (depth, radius, contrast), None if
            too few probes are near it.
    """

    kind: str
    centre: tuple[float, float]
    centre_ci: tuple[Interval, Interval]
    radius: float
    radius_ci: Interval
    extreme: float
    probability: float
    depth: DepthReading | None = None

    def as_dict(self) -> dict[str, object]:
        sphere = self.depth.as_dict() if self.depth is not None else {}
        return {
            "kind": self.kind,
            "center_mm": [self.centre[0] / MM, self.centre[1] / MM],
            "center_ci_mm": [[v / MM for v in axis] for axis in self.centre_ci],
            "radius_mm": self.radius / MM,
            "radius_ci_mm": [v / MM for v in self.radius_ci],
            "depth_mm": None,
            "depth_ci_mm": None,
            "extreme_kpa": self.extreme / 1e3,
            "probability": self.probability,
            **sphere,
        }


@dataclass(frozen=True)
class MapSummary:
    """A map's answer (SI: m, Pa); the grid's arrays are (GRID, GRID), y along the rows."""

    x: FloatArray
    y: FloatArray
    mean: FloatArray  # E (Pa), the posterior median exp(mean of log E)
    sd: FloatArray  # sd of log E
    p_above: FloatArray
    threshold: float  # Pa
    threshold_from_data: bool
    background: float  # Pa
    found: bool
    evidence: str
    centre: tuple[float, float] | None = None
    centre_ci: tuple[tuple[float, float], tuple[float, float]] | None = None
    radius: float | None = None
    radius_ci: tuple[float, float] | None = None
    apparent_radius: float | None = None  # the region's (equal area disc), m
    extent: Extent | None = None
    inclusions: tuple[Inclusion, ...] = ()  # every one the map reads (maps.inclusions)

    def inside(self, x: FloatArray, y: FloatArray) -> NDArray[np.bool_]:
        """Whether points (m, any shape) lie within the reported boundary: the extent's disc,
        or the region P(above) > 0.5 on the summary's grid without one (nothing if not
        found)."""
        if not self.found:
            return np.zeros(np.shape(x), dtype=bool)
        if self.extent is not None:
            c = self.extent.centre
            return np.asarray(np.hypot(x - c[0], y - c[1]) <= self.extent.radius)
        return np.asarray(self.p_above > 0.5)

    def as_dict(self) -> dict[str, object]:
        def mm(v: tuple[float, ...] | None) -> list[float] | None:
            return None if v is None else [float(a) / MM for a in v]

        def length(v: float | None) -> float | None:
            return None if v is None else v / MM

        return {
            "inclusion_found": self.found,
            "evidence": self.evidence,
            "inclusion_center_mm": mm(self.centre),
            "inclusion_center_ci_mm": (
                None if self.centre_ci is None else [mm(self.centre_ci[0]), mm(self.centre_ci[1])]
            ),
            "inclusion_radius_mm": length(self.radius),
            "inclusion_radius_ci_mm": mm(self.radius_ci),
            "apparent_radius_mm": length(self.apparent_radius),
            "extent": None if self.extent is None else self.extent.as_dict(),
            "threshold_kpa": self.threshold / 1e3,
            "threshold_from_data": self.threshold_from_data,
            "background_kpa": self.background / 1e3,
            "peak_kpa": float(np.max(self.mean)) / 1e3,
            "max_p_above": float(np.max(self.p_above)),
            "inclusions": [i.as_dict() for i in self.inclusions],
        }


def summarise(
    m: StiffnessMap,
    patch: Patch,
    *,
    threshold: float | None = None,
    min_rise: float = MIN_RISE,
    found_probability: float = FOUND_PROBABILITY,
    seed: int = 0,
) -> MapSummary:
    """The map's answer over ``patch`` (``threshold`` in Pa, None: from the data)."""
    x, y = patch.grid(GRID)
    points = patch.points(GRID)
    mean, sd = m.predict(points)
    t = log_threshold(m, mean, threshold, min_rise)
    p = above(mean, sd, t)
    shape = (GRID, GRID)
    base: dict[str, Any] = {
        "x": x,
        "y": y,
        "mean": np.exp(mean).reshape(shape),
        "sd": sd.reshape(shape),
        "p_above": p.reshape(shape),
        "threshold": math.exp(t),
        "threshold_from_data": threshold is None,
        "background": math.exp(m.background),
    }
    rise = math.exp(float(mean.max()) - m.background) - 1.0
    best = float(p.max())
    if best < found_probability:
        evidence = (
            f"no inclusion found: nowhere above {math.exp(t) / 1e3:.4g} kPa with probability "
            f">= {found_probability:g} (at most {best:.3f}); the map's peak is "
            f"{100 * rise:+.1f} % of the background"
        )
        return MapSummary(**base, found=False, evidence=evidence)
    region = peak_region(p > 0.5, mean)
    weight = np.where(region, mean - t, 0.0)
    centre = (
        float(points[:, 0] @ weight / weight.sum()),
        float(points[:, 1] @ weight / weight.sum()),
    )
    apparent = math.sqrt(region.sum() * _cell(patch, GRID) / math.pi)
    reach = apparent + m.length_scale
    centre_ci, radius_ci = _intervals(m, patch, t, np.random.default_rng(seed), centre, reach)
    evidence = (
        f"inclusion found: above {math.exp(t) / 1e3:.4g} kPa with probability {best:.3f}; the "
        f"map's peak is {100 * rise:+.1f} % of the background"
    )
    return MapSummary(
        **base,
        found=True,
        evidence=evidence,
        centre=centre,
        centre_ci=centre_ci,
        **_radii(apparent, radius_ci, _extent(m, patch, centre, apparent)),
    )


def _radii(apparent: float, drawn: tuple[float, float], extent: Extent | None) -> dict[str, Any]:
    """The summary's radius fields: the extent's disc where there is one, its interval from
    the region's draws' low end to the disc's high one; else the region's, as drawn."""
    if extent is None:
        return {"radius": apparent, "radius_ci": drawn, "apparent_radius": apparent}
    r = extent.radius
    spans = (min(drawn[0], r), r + Z95 * extent.radius_se)
    return {"radius": r, "radius_ci": spans, "apparent_radius": apparent, "extent": extent}


def _extent(
    m: StiffnessMap, patch: Patch, centre: tuple[float, float], radius: float
) -> Extent | None:
    """The disc through the tip's contact (``extent``), None where the probes cannot carry it
    (no contact radii, too few), it is unbounded, or it leaves the patch (its centre outside,
    its radius past half the patch's diagonal): the region stands then."""
    try:
        ext = fit_extent(m.used, centre, radius)
    except ExtentError:
        return None
    (cx, cy), r = ext.centre, ext.radius
    within = patch.x_min <= cx <= patch.x_max and patch.y_min <= cy <= patch.y_max
    return ext if within and r <= 0.5 * patch.diagonal and math.isfinite(ext.radius_se) else None


def peak_region(region: NDArray[np.bool_], mean: FloatArray) -> NDArray[np.bool_]:
    """The connected part of ``region`` (flat, on the summary's grid) holding its highest
    mean: one inclusion's, when the map holds several."""
    labels, _ = ndimage.label(region.reshape(GRID, GRID))
    flat = labels.ravel()
    top = int(np.argmax(np.where(region, mean, -np.inf)))
    return np.asarray(flat == flat[top])


def above(mean: FloatArray, sd: FloatArray, t: float) -> FloatArray:
    """P(log E > t) of a normal posterior with ``mean`` and ``sd``."""
    return np.asarray(ndtr((mean - t) / np.maximum(sd, 1e-12)), dtype=np.float64)


def log_threshold(
    m: StiffnessMap, mean: FloatArray, threshold: float | None, min_rise: float = MIN_RISE
) -> float:
    """The threshold on log E: the given one, or half-way from the background to the peak
    and at least ``min_rise`` above the background."""
    if threshold is not None:
        if not threshold > 0:
            raise ValueError(f"threshold must be > 0 Pa, got {threshold!r}")
        return math.log(threshold)
    floor = m.background + math.log1p(min_rise)
    return max(m.background + 0.5 * (float(np.max(mean)) - m.background), floor)


def _cell(patch: Patch, n: int) -> float:
    return patch.area / (n - 1) ** 2


def _intervals(
    m: StiffnessMap,
    patch: Patch,
    t: float,
    rng: np.random.Generator,
    centre: tuple[float, float],
    reach: float,
) -> tuple[tuple[tuple[float, float], tuple[float, float]], tuple[float, float]]:
    """95 % intervals of the centre (x and y) and the radius over posterior draws, each draw's
    region taken within ``reach`` of ``centre`` (a draw with no point above the threshold
    there counts as radius 0 and no centre)."""
    points = patch.points(DRAW_GRID)
    return drawn(m.draws(points, DRAWS, rng), points, patch, t, 1.0, centre, reach)


def drawn(
    draws: FloatArray,
    points: FloatArray,
    patch: Patch,
    t: float,
    sign: float,
    centre: tuple[float, float],
    reach: float,
) -> tuple[tuple[tuple[float, float], tuple[float, float]], tuple[float, float]]:
    """95 % intervals of a region's centre (x, y) and radius over posterior ``draws`` (n, k)
    of log E at ``points`` (k, 2) on the draw grid: each draw's region is where it is past
    ``t`` (above for ``sign`` 1, below for -1) within ``reach`` of ``centre``, its centre the
    centroid weighted by how far past."""
    close = np.hypot(points[:, 0] - centre[0], points[:, 1] - centre[1]) <= reach
    weight = (sign * (draws[:, close] - t)).clip(min=0.0)
    total = weight.sum(axis=1)
    some = total > 0
    cx = (weight[some] @ points[close, 0]) / total[some]
    cy = (weight[some] @ points[close, 1]) / total[some]
    radius = np.sqrt(np.count_nonzero(weight, axis=1) * _cell(patch, DRAW_GRID) / math.pi)
    if not some.any():
        nan = (math.nan, math.nan)
        return (nan, nan), (0.0, float(np.percentile(radius, 97.5)))

    def ci(v: FloatArray) -> tuple[float, float]:
        lo, hi = np.percentile(v, [2.5, 97.5])
        return float(lo), float(hi)

    return (ci(cx), ci(cy)), ci(radius)


GRID_FIELDS = ("x", "y", "z", "modulus_kpa", "sd", "p_above")
PROBE_FIELDS = ("x", "y", "z", "modulus_kpa", "order")


def grid_frame(
    probes: Sequence[Probe],
    patch: Patch,
    *,
    threshold: float | None = None,
    length_scale_max: float = LENGTH_SCALE_MAX,
) -> list[FloatArray] | None:
    """The map of ``probes`` as columns of :data:`GRID_FIELDS` over the summary's grid (m,
    kPa; z = 0, the surface), None while too few probes give a number: what a recording and
    the live view draw after each probe."""
    if sum(p.usable for p in probes) < MIN_PROBES:
        return None
    try:
        m = StiffnessMap.fit(list(probes), length_scale_max=length_scale_max)
    except MapError:
        return None
    points = patch.points(GRID)
    mean, sd = m.predict(points)
    p = above(mean, sd, log_threshold(m, mean, threshold))
    return [points[:, 0], points[:, 1], np.zeros(len(points)), np.exp(mean) / 1e3, sd, p]


def probe_frame(probes: Sequence[Probe]) -> list[FloatArray]:
    """The probes as columns of :data:`PROBE_FIELDS` (kPa, NaN without a number; order from 1)."""
    xy = np.array([[p.x, p.y] for p in probes], dtype=np.float64).reshape(-1, 2)
    moduli = np.array([math.nan if p.modulus is None else p.modulus / 1e3 for p in probes])
    order = np.arange(1.0, len(probes) + 1)
    return [xy[:, 0], xy[:, 1], np.zeros(len(probes)), moduli, order]
