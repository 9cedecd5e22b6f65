"""Where a map probes next: a raster, random points, or actively where the boundary is unsure.

Every strategy answers :meth:`Strategy.next` with the next point (m) or None (done: the plan is
spent, or the boundary is known). The active one (:class:`Active`) starts on a 3 x 3 raster of
the patch's cells, then asks the map (``gp``) for the candidate on a 41 x 41 grid with the
largest straddle score, ``1.96 sd - |mean - threshold|`` on log E (Bryan et al. 2005: high where
the process is unsure and near the level set), less a travel penalty in proportion to the
distance from the last probe (RASEC: half the travel at equal F1). It stops when the boundary
is known to ``tolerance``: the area still uncertain (0.05 < P(above) < 0.95) is at most
``tolerance`` times the boundary's length (with no region, a ``tolerance``-wide square).
``active-all`` straddles two more levels, 10 % above the background (a weaker nodule beside a
stronger one) and half-way from the background down to the map's lowest point, at least 10 %
under it (a cyst), and stops when every boundary is known (issue 57)::

    plan = Active(patch, max_probes=30)
    while (point := plan.next(probes)) is not None:
        probes.append(probe_at(point))
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from .gp import LENGTH_SCALE_MAX, MIN_PROBES, MapError, Patch, StiffnessMap
from .probes import Probe
from .region import GRID, MIN_RISE, above, log_threshold

FloatArray = NDArray[np.float64]
Point = tuple[float, float]
STRATEGIES = ("active", "active-all", "raster", "random")
Z = 1.96
START = 3  # the active plan's first raster, START x START cells


class Strategy(Protocol):
    """A map's plan: the next point to probe (m), or None when it is done."""

    def next(self, probes: Sequence[Probe]) -> Point | None: ...


def raster_points(patch: Patch, n: int) -> list[Point]:
    """The centres of a k x k grid of cells (k the largest with k^2 <= n), row by row in a
    serpentine (each row the other way: the shortest travel)."""
    k = max(1, math.isqrt(n))
    dx, dy = (patch.x_max - patch.x_min) / k, (patch.y_max - patch.y_min) / k
    out: list[Point] = []
    for j in range(k):
        cols = range(k) if j % 2 == 0 else range(k - 1, -1, -1)
        out.extend((patch.x_min + (i + 0.5) * dx, patch.y_min + (j + 0.5) * dy) for i in cols)
    return out


class Planned:
    """A fixed list of points, probed in order (the raster and random baselines)."""

    def __init__(self, points: Sequence[Point]) -> None:
        self.points = list(points)

    def next(self, probes: Sequence[Probe]) -> Point | None:
        return self.points[len(probes)] if len(probes) < len(self.points) else None


def raster(patch: Patch, max_probes: int) -> Planned:
    return Planned(raster_points(patch, max_probes))


def random_plan(patch: Patch, max_probes: int, seed: int = 0) -> Planned:
    rng = np.random.default_rng(seed)
    xy = rng.uniform([patch.x_min, patch.y_min], [patch.x_max, patch.y_max], (max_probes, 2))
    return Planned([(float(a), float(b)) for a, b in xy])


class Active:
    """Straddle sampling with a travel penalty (the module docstring).

    Args:
        patch: where to probe; max_probes: the budget.
        threshold: the level set's E (Pa), None: from the data (``region.log_threshold``).
        tolerance: the boundary's tolerance (m); travel_penalty: log E per patch diagonal of
            travel; min_spacing: no probe closer than this to another (m); length_scale_max: the
            map's (``gp``).
    """

    def __init__(
        self,
        patch: Patch,
        max_probes: int,
        *,
        threshold: float | None = None,
        tolerance: float = 0.5e-3,
        travel_penalty: float = 0.05,
        min_spacing: float = 0.5e-3,
        seed: int = 0,
        length_scale_max: float = LENGTH_SCALE_MAX,
        soft: bool = False,
    ) -> None:
        self.patch, self.max_probes, self.threshold = patch, max_probes, threshold
        self.soft = soft  # straddle the soft level too (``active-all``: cysts as well)
        self.tolerance, self.travel_penalty, self.min_spacing = (
            tolerance,
            travel_penalty,
            min_spacing,
        )
        self.seed, self.length_scale_max = seed, length_scale_max
        self.start = raster_points(patch, START * START)
        self.candidates = patch.points(GRID)
        self.stopped = ""  # why it stopped early ("" while it has not)

    def next(self, probes: Sequence[Probe]) -> Point | None:
        if len(probes) >= self.max_probes:
            return None
        if len(probes) < len(self.start):
            return self.start[len(probes)]
        try:
            m = StiffnessMap.fit(
                list(probes), seed=self.seed, length_scale_max=self.length_scale_max
            )
        except MapError:  # too few numbers yet: go on with what a raster would do
            return self._fallback(probes)
        mean, sd = m.predict(self.candidates)
        levels = [(log_threshold(m, mean, self.threshold), 1.0)]
        if self.soft:
            levels += self._other_levels(m, mean)
        if all(self._known(mean, sd, t, sign) for t, sign in levels):
            self.stopped = f"boundary known to {self.tolerance * 1e3:g} mm"
            return None
        last = np.array([probes[-1].x, probes[-1].y])
        travel = np.hypot(*(self.candidates - last).T) / self.patch.diagonal
        straddle = np.max([Z * sd - np.abs(mean - t) for t, _ in levels], axis=0)
        score = straddle - self.travel_penalty * travel
        score[self._too_close(probes)] = -np.inf
        best = int(np.argmax(score))
        return float(self.candidates[best, 0]), float(self.candidates[best, 1])

    @staticmethod
    def _other_levels(m: StiffnessMap, mean: FloatArray) -> list[tuple[float, float]]:
        """``active-all``'s levels beside the threshold: 10 % above the background (a weaker
        nodule beside a stronger one reads between the two), and half-way down to the lowest
        point, at least 10 % under the background (a cyst); each with its side."""
        floor = m.background + math.log1p(MIN_RISE)
        low = m.background + 0.5 * (float(np.min(mean)) - m.background)
        return [(floor, 1.0), (min(low, m.background - math.log1p(MIN_RISE)), -1.0)]

    def _known(self, mean: FloatArray, sd: FloatArray, t: float, sign: float = 1.0) -> bool:
        band, length = level_band(self.patch, mean, sd, t, sign)
        return band <= self.tolerance * max(length, self.tolerance)

    def _too_close(self, probes: Sequence[Probe]) -> NDArray[np.bool_]:
        xy = np.array([[p.x, p.y] for p in probes])
        d = np.hypot(
            self.candidates[:, None, 0] - xy[None, :, 0],
            self.candidates[:, None, 1] - xy[None, :, 1],
        )
        return np.asarray(d.min(axis=1) < self.min_spacing)

    def _fallback(self, probes: Sequence[Probe]) -> Point | None:
        extra = raster_points(self.patch, (START + 1) ** 2)
        tried = {(round(p.x, 9), round(p.y, 9)) for p in probes}
        for point in extra:
            if (round(point[0], 9), round(point[1], 9)) not in tried:
                return point
        self.stopped = f"fewer than {MIN_PROBES} probes gave a number"
        return None


def level_band(
    patch: Patch, mean: FloatArray, sd: FloatArray, t: float, sign: float = 1.0
) -> tuple[float, float]:
    """How well the level ``t`` of log E is known over ``patch`` (``mean`` and ``sd`` on its
    :data:`GRID` points): the area still uncertain, 0.05 < P(past t) < 0.95 (m^2), and the
    length of the region's boundary, P > 0.5 (m); past is above for ``sign`` 1, below for -1."""
    p = above(sign * mean, sd, sign * t).reshape(GRID, GRID)
    cell = patch.area / (GRID - 1) ** 2
    band = float(np.count_nonzero((p > 0.05) & (p < 0.95))) * cell
    region = p > 0.5
    edge = region & ~_interior(region)
    return band, float(np.count_nonzero(edge)) * math.sqrt(cell)


def _interior(region: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """Cells of ``region`` whose four neighbours are in it too (the patch's edge counts as in)."""
    padded = np.pad(region, 1, mode="edge")
    return np.asarray(
        region & padded[:-2, 1:-1] & padded[2:, 1:-1] & padded[1:-1, :-2] & padded[1:-1, 2:]
    )


def plan_for(
    strategy: str,
    patch: Patch,
    max_probes: int,
    *,
    seed: int = 0,
    threshold: float | None = None,
    length_scale_max: float = LENGTH_SCALE_MAX,
) -> Strategy:
    """The plan named ``strategy`` (one of :data:`STRATEGIES`)."""
    if strategy in ("active", "active-all"):
        return Active(
            patch,
            max_probes,
            threshold=threshold,
            seed=seed,
            length_scale_max=length_scale_max,
            soft=strategy == "active-all",
        )
    if strategy == "raster":
        return raster(patch, max_probes)
    if strategy == "random":
        return random_plan(patch, max_probes, seed)
    raise ValueError(f"strategy must be one of {STRATEGIES}, got {strategy!r}")
