"""A tip anywhere over one inclusion: its factor interpolated in the tip's distance from it.

A map probes a patch point by point, and every new distance between the tip and an inclusion's
vertical axis is a new three-dimensional solve (10-100 s, :mod:`sim.fem3d.table`). A sphere in
a layer that is wide against the tip is seen the same from every point at the same distance, so
the factor is solved once at fixed distances (:data:`OFFSET_NODES`, in tip radii) and read in
between by linear interpolation at each depth; beyond the last node it is the last node's
(there the factor is within a few tenths of a percent of one: docs/inclusions.md measures the
interpolation against solves between the nodes). Only a sample with one inclusion has such a
world: two spheres are not seen the same from every point at one distance.

Usage (what ``sim.sample_law.map_world`` builds for a probe)::

    world = MapWorld(layer, solid=on_axis, offset=hypot(x - xc, y - yc) / R)
    law = FeTissueLaw(world, modulus=E, tip_radius=R)   # sim.fem.law
"""

from __future__ import annotations

import bisect
import functools
import hashlib
from dataclasses import dataclass, replace

import numpy as np

from ..fem.problem import LayerProblem, significant
from ..fem.table import ForceTable, load_table, table_key
from .problem import InclusionProblem
from .table import load_ratios, ratio_key
from .world import scaled_table

# distances (tip radii) of the 3-D solves a map interpolates between: dense where the factor
# changes fastest (over the sphere), sparse where it has nearly died away
OFFSET_NODES = (0.0, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0)


def on_axis(solid: InclusionProblem) -> InclusionProblem:
    """``solid`` with its one inclusion moved onto the tip's vertical axis (x = y = 0)."""
    if len(solid.inclusions) != 1:
        raise ValueError(
            f"a map's world holds one inclusion, got {len(solid.inclusions)}: two spheres are "
            "not seen the same from every point at one distance"
        )
    return replace(solid, inclusions=(replace(solid.inclusions[0], x=0.0, y=0.0),))


def node_problems(solid: InclusionProblem) -> list[InclusionProblem]:
    """The 3-D problems solved at :data:`OFFSET_NODES` (``solid``'s inclusion put on the axis,
    then the tip moved along x)."""
    centred = on_axis(solid)
    return [centred.seen_from(node, 0.0) if node else centred for node in OFFSET_NODES]


@dataclass(frozen=True)
class MapWorld:
    """A layer and its one inclusion, the tip ``offset`` tip radii from the inclusion's axis.

    Attributes:
        layer: the homogeneous layer as the world has it (material, base, contact).
        solid: the 3-D problem with the inclusion on the axis (:func:`on_axis`).
        offset: the tip's distance from the inclusion's vertical axis (units of R, >= 0).
    """

    layer: LayerProblem
    solid: InclusionProblem
    offset: float

    def __post_init__(self) -> None:
        if not self.offset >= 0.0:
            raise ValueError(f"offset must be >= 0 tip radii, got {self.offset!r}")
        if on_axis(self.solid) != self.solid:
            raise ValueError("a MapWorld's inclusion sits on the axis (use on_axis)")
        if self.layer.depths() != self.solid.depths():
            raise ValueError("the layer's and the 3-D problem's depths differ")

    @property
    def key(self) -> str:
        both = f"{table_key(self.layer)}|{ratio_key(self.solid)}|{significant(self.offset)}"
        return hashlib.sha256(both.encode()).hexdigest()[:16]

    def table(self) -> ForceTable:
        """The layer's forces times the factor interpolated at :attr:`offset`."""
        layer = load_table(self.layer)
        n = layer.depths.size
        return scaled_table(layer, factor_at(self.solid, self.offset)[:n], self.key)


def factor_at(solid: InclusionProblem, offset: float) -> np.ndarray:
    """The inclusion's factor at each tabulated depth, the tip ``offset`` tip radii from its
    axis (linear between :data:`OFFSET_NODES`, the last node's beyond them)."""
    nodes = _node_ratios(solid)
    k = bisect.bisect_right(OFFSET_NODES, offset) - 1
    if k >= len(OFFSET_NODES) - 1:
        return nodes[-1]
    lo, hi = OFFSET_NODES[k], OFFSET_NODES[k + 1]
    w = (offset - lo) / (hi - lo)
    return np.asarray((1.0 - w) * nodes[k] + w * nodes[k + 1])


@functools.lru_cache(maxsize=16)
def _node_ratios(solid: InclusionProblem) -> tuple[np.ndarray, ...]:
    return tuple(load_ratios(p).ratios for p in node_problems(solid))
