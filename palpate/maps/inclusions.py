"""Every inclusion a map holds: its stiff and its soft regions, each with centre and radius.

The summary (:mod:`maps.region`) answers for the map's highest region. A patch can hold
several nodules, and a cyst reads softer than the tissue around it, so the map is read again
against two levels, ``min_rise`` (10 %) above and below the background in log E. Each connected
region of the summary's grid where the posterior is past a level with probability over one half
is a candidate; it is an inclusion when its most certain point is past it with probability at
least ``found_probability`` (0.95), the summary's rule. For each, as the summary does for its
one: a threshold half-way (in log E) from the background to the region's own extreme, the
centroid of the region past it weighted by how far past, the equal-area radius, and 95 %
intervals from joint posterior draws, each draw's region taken near the inclusion (within its
radius and one length scale of the map). The first of the list is the summary's own inclusion,
with its extent (the disc through the tip's contact) where it has one; the rest by how far
their extreme reads from the background. Each inclusion's depth, sphere and contrast are then
read from the probes about it (:mod:`maps.depth`; ``depth`` None where too few probes are near
it), and a region whose probes a shift of the background explains as well as a sphere does is
dropped (but the summary's own)::

    found = find_inclusions(StiffnessMap.fit(probes), patch, summary)
    [(f.kind, f.centre, f.radius, f.depth and f.depth.depth) for f in found]
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage  # type: ignore[import-untyped,unused-ignore]

from .depth import read_depth
from .gp import Patch, StiffnessMap
from .region import (
    DRAW_GRID,
    DRAWS,
    FOUND_PROBABILITY,
    GRID,
    MIN_RISE,
    Inclusion,
    MapSummary,
    above,
    drawn,
)

FloatArray = NDArray[np.float64]


def find_inclusions(
    m: StiffnessMap,
    patch: Patch,
    summary: MapSummary,
    *,
    min_rise: float = MIN_RISE,
    found_probability: float = FOUND_PROBABILITY,
    seed: int = 0,
) -> list[Inclusion]:
    """Every stiff and soft inclusion of the map over ``patch``; ``summary``'s first."""
    points = patch.points(GRID)
    mean, sd = m.predict(points)
    near = patch.points(DRAW_GRID)
    draws = m.draws(near, DRAWS, np.random.default_rng(seed))
    found: list[Inclusion] = []
    for kind, sign in (("stiff", 1.0), ("soft", -1.0)):
        level = m.background + sign * math.log1p(min_rise)
        p = above(sign * mean, sd, sign * level)
        labels, n = ndimage.label((p > 0.5).reshape(GRID, GRID))
        for k in range(1, n + 1):
            for mask in split(labels.ravel() == k, sign * (mean - m.background)):
                best = float(p[mask].max())
                if best >= found_probability:
                    found.append(_read(kind, sign, m, patch, points, mean, mask, near, draws, best))
    found.sort(key=lambda f: -abs(math.log(f.extreme) - m.background))
    ordered = _summary_first(found, summary)
    own = bool(ordered) and summary.found and ordered[0].centre == summary.centre
    return with_depths(ordered, m, keep_first=own)


def with_depths(found: list[Inclusion], m: StiffnessMap, keep_first: bool) -> list[Inclusion]:
    """Each inclusion with its sphere read from the map's probes about it, the others' probes
    left to them. One the probes about it do not bear out is dropped, except the summary's own
    (``keep_first``): fewer than :data:`maps.depth.MIN_PROBES` of them (where the probes carry
    their contact radii: the map extrapolating into a corner it barely probed), or a shift of
    the background explains them as well as a sphere (:attr:`DepthReading.needed`: the corners
    of a patch whose background large inclusions lifted)."""
    judged = any(p.contact_radius is not None for p in m.used)
    out = []
    for k, f in enumerate(found):
        others = [g.centre for g in found if g is not f]
        reading = read_depth(m.used, f.centre, m.background, f.kind, others)
        borne = reading.needed if reading is not None else not judged
        if borne or (keep_first and k == 0):
            out.append(replace(f, depth=reading))
    return out


PEAK_CELLS = 5  # a peak is the highest point of the 5 x 5 cells about it (2 mm on 20 mm)
SADDLE = 0.5  # two peaks are two inclusions where the map between them falls half-way down


def split(mask: NDArray[np.bool_], rise: FloatArray) -> list[NDArray[np.bool_]]:
    """``mask`` (one connected region, flat on the summary's grid) split between its peaks:
    two nodules whose blurred footprints touch are one region at the 10 % level. A peak of
    ``rise`` (log E past the background, on the region's side) counts when the map along the
    straight line to every higher peak kept falls below it by :data:`SADDLE` of its own rise;
    each cell goes to the nearest peak kept."""
    grid = np.where(mask, rise, -np.inf).reshape(GRID, GRID)
    tops = np.flatnonzero((grid == ndimage.maximum_filter(grid, size=PEAK_CELLS)).ravel() & mask)
    kept: list[int] = []
    for top in sorted((int(c) for c in tops), key=lambda c: -rise[c]):
        if all(_valley(grid, top, other) < (1.0 - SADDLE) * rise[top] for other in kept):
            kept.append(top)
    if len(kept) < 2:
        return [mask]
    cells = np.flatnonzero(mask)
    ij = np.stack(np.unravel_index(cells, (GRID, GRID)), axis=1)
    peaks = np.stack(np.unravel_index(np.array(kept), (GRID, GRID)), axis=1)
    owner = np.argmin(((ij[:, None, :] - peaks[None, :, :]) ** 2).sum(axis=2), axis=1)
    parts = []
    for k in range(len(kept)):
        part = np.zeros_like(mask)
        part[cells[owner == k]] = True
        parts.append(part)
    return parts


def _valley(grid: FloatArray, a: int, b: int) -> float:
    """The lowest of ``grid`` (GRID x GRID) on the straight line between cells ``a`` and ``b``."""
    (ia, ja), (ib, jb) = np.unravel_index([a, b], grid.shape)
    n = 2 * max(abs(ib - ia), abs(jb - ja)) + 1
    i = np.rint(np.linspace(ia, ib, n)).astype(int)
    j = np.rint(np.linspace(ja, jb, n)).astype(int)
    return float(grid[i, j].min())


def _read(
    kind: str,
    sign: float,
    m: StiffnessMap,
    patch: Patch,
    points: FloatArray,
    mean: FloatArray,
    mask: NDArray[np.bool_],
    near: FloatArray,
    draws: FloatArray,
    probability: float,
) -> Inclusion:
    """One region's inclusion: its own half-way threshold, centroid, radius and intervals."""
    extreme = float(sign * np.max(sign * mean[mask]))
    t = m.background + 0.5 * (extreme - m.background)
    past = np.where(mask, sign * (mean - t), 0.0).clip(min=0.0)
    centre = (float(points[:, 0] @ past / past.sum()), float(points[:, 1] @ past / past.sum()))
    cell = patch.area / (GRID - 1) ** 2
    radius = math.sqrt(np.count_nonzero(past) * cell / math.pi)
    reach = radius + m.length_scale
    centre_ci, radius_ci = drawn(draws, near, patch, t, sign, centre, reach)
    return Inclusion(
        kind,
        centre,
        centre_ci,
        radius,
        radius_ci,
        math.exp(extreme),
        probability,
    )


def _summary_first(found: list[Inclusion], summary: MapSummary) -> list[Inclusion]:
    """The list with the summary's inclusion first, carrying the summary's centre, radius and
    intervals (its extent's disc), so the first entry and the summary's keys agree."""
    if not summary.found or summary.centre is None:
        return found
    assert summary.centre_ci is not None
    assert summary.radius is not None
    assert summary.radius_ci is not None
    cx, cy = summary.centre
    stiff = [f for f in found if f.kind == "stiff"]
    if not stiff:
        return found
    own = min(stiff, key=lambda f: math.hypot(f.centre[0] - cx, f.centre[1] - cy))
    first = Inclusion(
        "stiff",
        summary.centre,
        summary.centre_ci,
        summary.radius,
        summary.radius_ci,
        own.extreme,
        own.probability,
    )
    return [first, *(f for f in found if f is not own)]
