"""The world's force law over a layer with inclusions: the axisymmetric table times their effect.

``F(delta) = F_layer(delta) * F_3D(delta) / F_3D,ref(delta)``: ``F_layer`` is the homogeneous
layer's axisymmetric table (:mod:`sim.fem`: its material, linear or neo-Hookean, its contact,
frictionless or stuck, its mesh-converged accuracy), and the ratio is the inclusions' effect
from the three-dimensional linear, frictionless solve with and without them on one grid
(:mod:`sim.fem3d.table`). Without inclusions the law is the layer's exactly. The effect is a
small-strain one: on a neo-Hookean matrix the inclusion's own stiffening at finite strain is
not in it (docs/inclusions.md).

Usage::

    world = InclusionWorld(layer=LayerProblem(2.857, 11.43), solid=InclusionProblem(
        2.857, 11.43, inclusions=(Inclusion(0.0, 0.0, 1.5, 0.7, contrast=5.0),)))
    law = FeTissueLaw(world, modulus=314e3, tip_radius=3.5e-3)   # sim.fem.law
"""

from __future__ import annotations

import functools
import hashlib
from dataclasses import dataclass

import numpy as np

from ..fem.problem import LayerProblem
from ..fem.table import ForceTable, load_table, table_key
from .problem import InclusionProblem
from .table import load_ratios, ratio_key


@dataclass(frozen=True)
class InclusionWorld:
    """A layer (its axisymmetric problem) and the same layer with inclusions (its 3-D problem).

    Attributes:
        layer: the homogeneous layer as the world has it (material, base, contact).
        solid: the 3-D problem: the same thickness, width, Poisson's ratio, base and depths.
    """

    layer: LayerProblem
    solid: InclusionProblem

    def __post_init__(self) -> None:
        if self.layer.depths() != self.solid.depths():
            raise ValueError("the layer's and the 3-D problem's depths differ")

    @property
    def key(self) -> str:
        """The key of the combined table."""
        both = f"{table_key(self.layer)}|{ratio_key(self.solid.canonical_problem())}"
        return hashlib.sha256(both.encode()).hexdigest()[:16]

    def table(self) -> ForceTable:
        """The world's table: the layer's forces times the inclusions' factor."""
        return _table(self)


@functools.lru_cache(maxsize=64)
def _table(world: InclusionWorld) -> ForceTable:
    layer = load_table(world.layer)
    ratios = load_ratios(world.solid)
    n = layer.depths.size
    if not np.allclose(layer.depths, ratios.depths[:n], rtol=1e-12, atol=0.0):
        raise ValueError("the layer's and the 3-D problem's tabulated depths differ")
    return scaled_table(layer, ratios.ratios[:n], world.key, ratios.build_seconds)


def scaled_table(
    layer: ForceTable, factor: np.ndarray, key: str, extra_seconds: float = 0.0
) -> ForceTable:
    """The layer's table with its forces times ``factor`` (one per tabulated depth), under
    ``key``: a world with inclusions (this module's, ``offsets.MapWorld``)."""
    return ForceTable(
        key=key,
        problem=layer.problem,
        depths=layer.depths,
        forces=layer.forces * factor,
        contact_radii=layer.contact_radii,
        success=layer.success,
        message=layer.message,
        build_seconds=layer.build_seconds + extra_seconds,
    )
