"""The dimensionless indentation problem: a rigid sphere pressed into an elastic layer.

Lengths are in units of the sphere radius R and stresses in units of the layer's small-strain
Young's modulus E, so one solution serves every sample of the same shape: the force scales as
``F = E R^2 f(delta/R)`` (exactly for linear elasticity; for the neo-Hookean solid at a fixed
bulk/shear ratio, i.e. a fixed small-strain Poisson's ratio, because its energy is homogeneous
in the shear modulus).

Geometry (axisymmetric, coordinates (r, z), z up): the layer occupies ``0 <= r <= radius_ratio``,
``-thickness_ratio <= z <= 0``; the sphere's centre is at ``(0, 1 - delta)``. The layer rests on a
rigid base at ``z = -thickness_ratio`` (glued: ``bonded``; frictionless: ``sliding``); its lateral
edge is traction-free.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

MATERIALS = ("linear", "neo-hookean")
BASES = ("bonded", "sliding")
CONTACTS = ("frictionless", "stick")
THIN_STRAIN_MAX = 0.5
"""delta/h to which a neo-Hookean layer thinner than the tip is tabulated (``from_dimensions``)."""


@dataclass(frozen=True)
class LayerProblem:
    """Everything that changes a force-indentation table (with ``SOLVER_VERSION``).

    Attributes:
        thickness_ratio: layer thickness h / R (> 0).
        radius_ratio: lateral radius of the layer / R (> 1).
        poisson: small-strain Poisson's ratio in [0, 0.5] (0.5: incompressible, mixed u-p).
        material: ``"linear"`` (small strain, Sneddon's kinematics: the gap is vertical at the
            undeformed radius) or ``"neo-hookean"`` (finite strain, exact sphere gap).
        base: ``"bonded"`` or ``"sliding"`` (frictionless) rigid base.
        contact: ``"frictionless"`` or ``"stick"`` (full stick, the limit of Coulomb friction
            with a large coefficient: a node that touches the sphere stays on that point).
        depth_max: deepest tabulated depth delta / R.
        n_depths: number of tabulated depths (uniform in sqrt(delta / R)).
        resolution: mesh density (elements per contact radius at the contact edge, about).
        inclusion: a sphere on the axis, ``(depth, radius, contrast, poisson)`` of its centre
            below the surface, its radius (units of R), its Young's modulus over the layer's
            and its Poisson's ratio; None (the default, and left out of the table's key): a
            homogeneous layer. The three-dimensional world's reference (``sim.fem3d``).
    """

    thickness_ratio: float
    radius_ratio: float
    poisson: float = 0.45
    material: str = "linear"
    base: str = "bonded"
    contact: str = "frictionless"
    depth_max: float = 1.0
    n_depths: int = 20
    resolution: int = 6
    inclusion: tuple[float, float, float, float] | None = None

    def __post_init__(self) -> None:
        _check_choice("material", self.material, MATERIALS)
        _check_choice("base", self.base, BASES)
        _check_choice("contact", self.contact, CONTACTS)
        if not (math.isfinite(self.thickness_ratio) and self.thickness_ratio > 0):
            raise ValueError(f"thickness_ratio must be finite and > 0, got {self.thickness_ratio}")
        if not (math.isfinite(self.radius_ratio) and self.radius_ratio > 1):
            raise ValueError(f"radius_ratio must be finite and > 1, got {self.radius_ratio}")
        if not 0.0 <= self.poisson <= 0.5:
            raise ValueError(f"poisson must be in [0, 0.5], got {self.poisson}")
        if not 0 < self.depth_max <= 1.0:
            raise ValueError(f"depth_max must be in (0, 1], got {self.depth_max}")
        if self.n_depths < 3:
            raise ValueError(f"n_depths must be >= 3, got {self.n_depths}")
        if not 2 <= self.resolution <= 64:
            raise ValueError(f"resolution must be in [2, 64], got {self.resolution}")
        if self.inclusion is not None:
            depth, radius, contrast, nu = self.inclusion
            if not (0 < radius < depth and depth + radius < self.thickness_ratio):
                raise ValueError(f"inclusion {self.inclusion} must lie inside the layer")
            if not (contrast > 0 and 0.0 <= nu <= 0.5):
                raise ValueError(f"inclusion {self.inclusion}: contrast > 0, poisson in [0, 0.5]")

    @property
    def shear_modulus(self) -> float:
        """mu / E = 1 / (2 (1 + nu))."""
        return 0.5 / (1.0 + self.poisson)

    @property
    def bulk_compliance(self) -> float:
        """E / K = 3 (1 - 2 nu): 0 for an incompressible solid."""
        return 3.0 * (1.0 - 2.0 * self.poisson)

    def material_fields(
        self, r: FloatArray, z: FloatArray
    ) -> tuple[float | FloatArray, float | FloatArray]:
        """(mu / E, E / K) at the points (r, z): the layer's constants, or arrays of the points'
        shape with the inclusion's values inside it."""
        if self.inclusion is None:
            return self.shear_modulus, self.bulk_compliance
        depth, radius, contrast, nu = self.inclusion
        inside = r**2 + (z + depth) ** 2 <= radius**2
        shear = np.where(inside, contrast * 0.5 / (1.0 + nu), self.shear_modulus)
        bulk = np.where(inside, 3.0 * (1.0 - 2.0 * nu) / contrast, self.bulk_compliance)
        return shear, bulk

    def depths(self) -> list[float]:
        """The tabulated depths delta / R: uniform in s = sqrt(delta / R) from s_max / n."""
        s_max = math.sqrt(self.depth_max)
        return [(s_max * k / self.n_depths) ** 2 for k in range(1, self.n_depths + 1)]

    @classmethod
    def from_dimensions(
        cls, tip_radius: float, thickness: float, radius: float, **options: Any
    ) -> LayerProblem:
        """The problem of a sample in SI units (tip radius R, layer thickness h and lateral
        radius, m); the ratios are rounded to 9 significant digits so that the same sample
        written two ways (10 mm / 3.5 mm or 0.01 / 0.0035) names the same table. A
        neo-Hookean layer thinner than the tip is solved to delta/h = THIN_STRAIN_MAX unless
        ``depth_max`` is given (delta/R = 1 would press through it; its elements invert near
        delta/h = 0.6)."""
        if not (math.isfinite(tip_radius) and tip_radius > 0):
            raise ValueError(f"tip_radius must be finite and > 0, got {tip_radius}")
        ratio = significant(thickness / tip_radius)
        if options.get("material") == "neo-hookean" and ratio < 1.0:
            options.setdefault("depth_max", round(THIN_STRAIN_MAX * ratio, 6))
        return cls(
            thickness_ratio=ratio,
            radius_ratio=significant(radius / tip_radius),
            **options,
        )

    def as_dict(self) -> dict[str, Any]:
        """Plain-data form (what the table key hashes; no ``inclusion`` key when there is none,
        so the homogeneous layers keep their keys)."""
        out = asdict(self)
        if self.inclusion is None:
            del out["inclusion"]
        return out


def _check_choice(name: str, value: str, allowed: tuple[str, ...]) -> None:
    if value not in allowed:
        raise ValueError(f"{name} must be one of {allowed}, got {value!r}")


def significant(x: float) -> float:
    """``x`` to 9 significant digits: a ratio computed two ways (10 mm / 3.5 mm or 0.01 /
    0.0035, a position turned or moved) names the same table."""
    return float(f"{x:.9g}")
