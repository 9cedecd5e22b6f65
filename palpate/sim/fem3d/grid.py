"""The three-dimensional layer's mesh: a box of trilinear hexahedra graded toward what matters.

A tensor grid (every element an axis-aligned box, so its stiffness is a fixed combination of
reference matrices: :mod:`sim.fem3d.stiffness`), whose spacing along each axis is the smallest
that any feature asks for at that coordinate, growing linearly with the distance from it:

- the patch the tip can touch (``|x|, |y| <= patch``, ``z`` near the surface): ``fine``;
- every inclusion's extent along that axis: ``radius / per_radius``;
- elsewhere the spacing grows by ``growth`` per unit distance (a geometric grading), up to
  ``coarse``.

The origin of x and y (where a single trial indents) and the surface z = 0 are nodes. Lengths in
units of the tip radius R; the layer is ``[-width, width]^2 x [-thickness, 0]``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


@dataclass(frozen=True)
class Feature:
    """An interval ``[lo, hi]`` of one axis that wants elements no larger than ``size``."""

    lo: float
    hi: float
    size: float

    def spacing(self, x: float, growth: float) -> float:
        distance = max(self.lo - x, x - self.hi, 0.0)
        return self.size + growth * distance


def graded_axis(
    lo: float, hi: float, features: Sequence[Feature], growth: float, coarse: float
) -> FloatArray:
    """Nodes from ``lo`` to ``hi`` (both included, and 0 when inside) whose spacing at every
    point is at most what the nearest feature asks for there (``coarse`` at most); a last
    interval shorter than half its neighbour is merged into it."""

    def step(x: float) -> float:
        return min([coarse, *(f.spacing(x, growth) for f in features)])

    def march(start: float, end: float) -> list[float]:
        sign = 1.0 if end > start else -1.0
        nodes = [start]
        while sign * (end - nodes[-1]) > 1e-12:
            x = nodes[-1]
            s = step(x)
            s = min(s, step(x + sign * s))
            nodes.append(x + sign * s if sign * (end - x) > s else end)
        if len(nodes) > 2 and abs(nodes[-1] - nodes[-2]) < 0.5 * abs(nodes[-2] - nodes[-3]):
            del nodes[-2]
        return nodes

    if lo < 0.0 < hi:
        left = march(0.0, lo)[::-1]
        return np.asarray(left[:-1] + march(0.0, hi))
    return np.asarray(march(lo, hi))


@dataclass(frozen=True)
class HexGrid:
    """A tensor grid of boxes: node coordinates along x (nx,), y (ny,) and z (nz,), z increasing
    to the surface at 0. Node (i, j, k) is number ``i + nx (j + ny k)``."""

    x: FloatArray
    y: FloatArray
    z: FloatArray

    @property
    def shape(self) -> tuple[int, int, int]:
        return self.x.size, self.y.size, self.z.size

    @property
    def n_nodes(self) -> int:
        return self.x.size * self.y.size * self.z.size

    @property
    def n_elements(self) -> int:
        return (self.x.size - 1) * (self.y.size - 1) * (self.z.size - 1)

    def node(self, i: IntArray, j: IntArray, k: IntArray) -> IntArray:
        nx, ny, _ = self.shape
        return np.asarray(i + nx * (j + ny * k), dtype=np.int64)

    def elements(self) -> IntArray:
        """(nel, 8) corner nodes of every box, local corner l = a + 2 b + 4 c for the offsets
        (a, b, c) in {0, 1}^3 along (x, y, z)."""
        nx, ny, nz = self.shape
        i, j, k = (
            v.ravel(order="F")
            for v in np.meshgrid(
                np.arange(nx - 1), np.arange(ny - 1), np.arange(nz - 1), indexing="ij"
            )
        )
        corners = [self.node(i + a, j + b, k + c) for c in (0, 1) for b in (0, 1) for a in (0, 1)]
        return np.stack(corners, axis=1)

    def sizes(self) -> FloatArray:
        """(nel, 3) edge lengths of every box (same order as :meth:`elements`)."""
        dx, dy, dz = np.diff(self.x), np.diff(self.y), np.diff(self.z)
        hx, hy, hz = np.meshgrid(dx, dy, dz, indexing="ij")
        return np.stack([v.ravel(order="F") for v in (hx, hy, hz)], axis=1)

    def centres(self) -> FloatArray:
        """(nel, 3) box centres."""
        cx = 0.5 * (self.x[1:] + self.x[:-1])
        cy = 0.5 * (self.y[1:] + self.y[:-1])
        cz = 0.5 * (self.z[1:] + self.z[:-1])
        gx, gy, gz = np.meshgrid(cx, cy, cz, indexing="ij")
        return np.stack([v.ravel(order="F") for v in (gx, gy, gz)], axis=1)


def nested_dissection(shape: tuple[int, int, int], leaf: int = 16) -> IntArray:
    """An elimination order of the grid's nodes: geometric nested dissection (split the longest
    index range at a middle plane, order both halves recursively, the plane last). On the
    layer's grids it makes SuperLU's factor 1.7x sparser and 3x faster than its own minimum
    degree ordering (86,975 unknowns: 22 s against 73 s; docs/inclusions.md)."""
    nx, ny, _ = shape
    out: list[IntArray] = []

    def block(ranges: list[tuple[int, int]]) -> IntArray:
        i, j, k = np.meshgrid(*(np.arange(lo, hi) for lo, hi in ranges), indexing="ij")
        return np.asarray((i + nx * (j + ny * k)).ravel(order="F"), dtype=np.int64)

    stack: list[tuple[list[tuple[int, int]], bool]] = [([(0, n) for n in shape], False)]
    while stack:  # iterative post-order: halves first, then their separator
        ranges, emit = stack.pop()
        dims = [hi - lo for lo, hi in ranges]
        if emit or int(np.prod(dims)) <= leaf or max(dims) < 3:
            out.append(block(ranges))
            continue
        a = int(np.argmax(dims))
        lo, hi = ranges[a]
        mid = (lo + hi) // 2
        parts = [list(ranges) for _ in range(3)]
        parts[0][a], parts[1][a], parts[2][a] = (lo, mid), (mid + 1, hi), (mid, mid + 1)
        stack += [(parts[2], True), (parts[1], False), (parts[0], False)]
    return np.concatenate(out)
