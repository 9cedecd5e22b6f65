"""The dimensionless three-dimensional problem: a rigid sphere on a layer holding inclusions.

Lengths in units of the tip radius R, moduli in units of the matrix's Young's modulus E (as in
:mod:`sim.fem.problem`): ``F = E R^2 f(delta / R)`` for a fixed geometry. The layer is
``[-width, width]^2 x [-thickness, 0]`` on a rigid base (``bonded`` or ``sliding``); the tip
indents at the surface point (0, 0) along -z; each inclusion is a sphere bonded to the matrix.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..fem.problem import BASES, LayerProblem, significant

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Inclusion:
    """A spherical inclusion (units of R and of the matrix's E).

    Attributes:
        x, y: its centre's position along the surface, from the point the tip indents.
        depth: its centre's depth below the surface (> radius: it lies under the surface).
        radius: its radius.
        contrast: its Young's modulus over the matrix's.
        poisson: its Poisson's ratio.
    """

    x: float
    y: float
    depth: float
    radius: float
    contrast: float
    poisson: float = 0.45

    def __post_init__(self) -> None:
        values = (self.x, self.y, self.depth, self.radius, self.contrast)
        if not all(math.isfinite(v) for v in values):
            raise ValueError(f"inclusion values must be finite, got {self}")
        if not (self.radius > 0 and self.contrast > 0):
            raise ValueError(f"inclusion radius and contrast must be > 0, got {self}")
        if self.depth <= self.radius:
            raise ValueError(f"an inclusion must lie below the surface (depth > radius): {self}")
        if not 0.0 <= self.poisson <= 0.5:
            raise ValueError(f"inclusion poisson must be in [0, 0.5], got {self.poisson}")

    @property
    def centre(self) -> FloatArray:
        return np.array([self.x, self.y, -self.depth])

    @property
    def offset(self) -> float:
        """Lateral distance of its centre from the indented point."""
        return math.hypot(self.x, self.y)


@dataclass(frozen=True)
class InclusionProblem:
    """Everything that changes a three-dimensional force table (with ``SOLVER_VERSION``).

    Attributes:
        thickness_ratio: layer thickness / R.
        radius_ratio: half-width of the square layer / R (a sample's lateral radius).
        poisson: the matrix's Poisson's ratio.
        base: ``"bonded"`` or ``"sliding"``.
        inclusions: the spheres it holds (none: the homogeneous layer, the reference).
        depth_max, n_depths: the tabulated depths, as :class:`~sim.fem.problem.LayerProblem`.
        fine: element size over the patch the tip can touch (units of R).
    """

    thickness_ratio: float
    radius_ratio: float
    poisson: float = 0.45
    base: str = "bonded"
    inclusions: tuple[Inclusion, ...] = field(default=())
    depth_max: float = 1.0
    n_depths: int = 20
    fine: float = 0.1

    def __post_init__(self) -> None:
        if self.base not in BASES:
            raise ValueError(f"base must be one of {BASES}, got {self.base!r}")
        if not (self.thickness_ratio > 0 and self.radius_ratio > 1):
            raise ValueError("thickness_ratio must be > 0 and radius_ratio > 1")
        if not 0.0 <= self.poisson <= 0.5:
            raise ValueError(f"poisson must be in [0, 0.5], got {self.poisson}")
        if not 0.01 <= self.fine <= 0.5:
            raise ValueError(f"fine must be in [0.01, 0.5], got {self.fine}")
        for inc in self.inclusions:
            if inc.depth + inc.radius >= self.thickness_ratio:
                raise ValueError(
                    f"inclusion {inc} reaches the base (thickness {self.thickness_ratio})"
                )
            if max(abs(inc.x), abs(inc.y)) + inc.radius >= self.radius_ratio:
                raise ValueError(f"inclusion {inc} reaches the sample's edge")

    def layer(self, **options: Any) -> LayerProblem:
        """The axisymmetric problem of the same homogeneous layer (``options``: material,
        contact, resolution)."""
        return LayerProblem(
            thickness_ratio=self.thickness_ratio,
            radius_ratio=self.radius_ratio,
            poisson=self.poisson,
            base=self.base,
            depth_max=self.depth_max,
            n_depths=self.n_depths,
            **options,
        )

    def depths(self) -> list[float]:
        return self.layer().depths()

    def seen_from(self, x: float, y: float) -> InclusionProblem:
        """The problem of a probe at (x, y) on the surface (units of R): the same layer, its
        inclusions placed relative to that point (the square layer is re-centred on it: its
        edge is far from what the probe feels, docs/inclusions.md). A map's probes::

            for x, y in points:
                ratios = load_ratios(problem.seen_from(x, y))
        """
        moved = tuple(
            replace(i, x=significant(i.x - x), y=significant(i.y - y)) for i in self.inclusions
        )
        return replace(self, inclusions=moved)

    def canonical_problem(self) -> InclusionProblem:
        """The same problem in the frame its solve uses (:meth:`canonical`), so that probes at
        the same distance from an inclusion share one table."""
        symmetry, inclusions = self.canonical()
        if symmetry != "half":
            return self
        turned = tuple(replace(i, x=significant(i.x), y=0.0) for i in inclusions)
        return replace(self, inclusions=turned)

    def canonical(self) -> tuple[str, tuple[Inclusion, ...]]:
        """The symmetry the solve can use and the inclusions turned into its frame.

        ``"quarter"``: no inclusion off the indented point's vertical (mirror planes x = 0 and
        y = 0); ``"half"``: every inclusion on one vertical plane through it, turned about the
        vertical onto y = 0 (mirror plane y = 0); ``"full"`` otherwise. Turning the inclusions
        about the vertical leaves the square layer's edges where they are: the sample's edge is
        far and only approximated by the square anyway (docs/inclusions.md)."""
        off = [inc for inc in self.inclusions if inc.offset > 1e-12]
        if not off:
            return "quarter", self.inclusions
        ux, uy = off[0].x / off[0].offset, off[0].y / off[0].offset
        turned = tuple(
            Inclusion(
                ux * inc.x + uy * inc.y,
                -uy * inc.x + ux * inc.y,
                inc.depth,
                inc.radius,
                inc.contrast,
                inc.poisson,
            )
            for inc in self.inclusions
        )
        if all(abs(inc.y) <= 1e-9 for inc in turned):
            return "half", tuple(replace(inc, y=0.0) for inc in turned)
        return "full", self.inclusions

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)
