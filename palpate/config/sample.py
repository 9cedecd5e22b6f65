"""A tissue sample: what the world is (truth), where it is, and what the operator believes.

A scene's ``samples[]`` entry describes the world's truth: modulus, Poisson's ratio, layer
thickness and bonding, material, viscoelasticity, the surface's pose and friction. The
estimator is never told the truth: it is told what the operator believes, the ``assumed:``
block (:class:`AssumedConfig`), or, without one, the sample's own values. So a scene can make
the belief wrong, as it is on a real bench::

    samples:
      - {name: S8, modulus_kpa: 314.53, thickness_mm: 6, bonded: false, poisson: 0.45,
         assumed: {thickness_mm: [5, 20], bonded: unknown, poisson: [0.40, 0.50]}}

Units are in the key when not SI; the SI values are properties without the suffix.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

from .loader import limits
from .schema import MM

KPA = 1e3
UNKNOWN = "unknown"
HALF_SPACE = "half-space"

Range = tuple[float, float]


def _check_range(key: str, value: object, lo: float, hi: float) -> None:
    if isinstance(value, tuple) and not lo <= value[0] <= value[1] <= hi:
        raise ValueError(f"{key}: a range [min, max] needs {lo} <= min <= max <= {hi}, got {value}")


@dataclass(frozen=True)
class AssumedConfig:
    """What the operator believes about a sample; the estimator is told this.

    Each key is a value, a ``[min, max]`` range or ``unknown``; ``thickness_mm`` may also be
    ``half-space``; ``curvature_radius_mm`` is a convex surface's radius (probing fits a sphere
    of it, the contact law takes the effective radius; ``unknown``: a plane is fitted unless
    the touches show a sphere, as for a flat sample). A key left out (null) means, in a scene,
    the sample's own value (the operator knows it), and on the bench: thickness, bonding and
    radius ``unknown``, Poisson's ratio the trial's ``poisson``. The estimate's interval
    carries what a range or ``unknown`` leaves open (profiled or marginalised), not only the
    FBG noise.
    """

    thickness_mm: float | Range | Literal["unknown", "half-space"] | None = field(
        default=None, metadata=limits(gt=0, le=1000)
    )
    bonded: bool | Literal["unknown"] | None = None
    poisson: float | Range | Literal["unknown"] | None = field(
        default=None, metadata=limits(ge=0, le=0.5)
    )
    curvature_radius_mm: float | Range | Literal["unknown"] | None = field(
        default=None, metadata=limits(gt=0, le=1e4)
    )
    material: Literal["linear", "neo-hookean"] | None = None
    friction: Literal["frictionless", "sticking", "unknown"] | None = None

    def validate(self) -> None:
        _check_range("thickness_mm", self.thickness_mm, 0.0, 1000.0)
        _check_range("poisson", self.poisson, 0.0, 0.5)
        _check_range("curvature_radius_mm", self.curvature_radius_mm, 1e-9, 1e4)

    def surface_radius(self, own: float | None) -> tuple[float, float] | None:
        """The convex surface's radius the operator believes, (min, max) in m, or None (a flat
        or an unknown surface: probing fits a plane, a sphere only where the touches show one).
        ``own``: the radius (m) a left-out key stands for (a scene's sample's own)."""
        r = self.curvature_radius_mm
        if r is None:
            return None if own is None else (own, own)
        if isinstance(r, tuple):
            return (r[0] * MM, r[1] * MM)
        if isinstance(r, int | float):
            return (r * MM, r * MM)
        return None


@dataclass(frozen=True)
class InclusionConfig:
    """A stiff (or soft) sphere inside a sample's layer: a tumour in parenchyma, a fibrotic
    focus. ``center_mm``: (x, y, depth) of its centre, x and y along the surface from the point
    where a single trial indents (the sample's origin), the depth below the surface;
    ``radius_mm``; its own ``modulus_kpa`` and ``poisson``. The world feels it
    (``sim.fem3d``); the estimator is never told it exists::

        inclusions:
          - {center_mm: [0, 0, 5], radius_mm: 2.5, modulus_kpa: 1500}
    """

    center_mm: tuple[float, float, float] = field(metadata=limits(ge=-1000, le=1000))
    radius_mm: float = field(metadata=limits(gt=0, le=1000))
    modulus_kpa: float = field(metadata=limits(gt=0, le=1e6))
    poisson: float = field(default=0.45, metadata=limits(ge=0, le=0.5))

    def validate(self) -> None:
        if self.center_mm[2] <= self.radius_mm:
            raise ValueError(
                f"center_mm: the depth {self.center_mm[2]:g} mm must exceed radius_mm "
                f"{self.radius_mm:g} (the inclusion lies below the surface)"
            )

    @property
    def center(self) -> tuple[float, float, float]:
        x, y, depth = self.center_mm
        return (x * MM, y * MM, depth * MM)

    @property
    def radius(self) -> float:
        return self.radius_mm * MM

    @property
    def modulus(self) -> float:
        return self.modulus_kpa * KPA


@dataclass(frozen=True)
class SampleConfig:
    """A tissue phantom as the world has it, and where it sits.

    Truth: ``modulus_kpa``, ``poisson``, ``thickness_mm`` (null = half-space) on a rigid base,
    ``bonded`` to it or sliding, ``material`` (linear elastic or neo-Hookean),
    ``lateral_radius_mm`` (the sample's finite lateral size), a relaxation (``relaxation``:
    ``sls``, a standard linear solid, or ``power-law``, ``G = r + (1 - r)(1 + t/tau)^-beta`` with
    ``relaxation_exponent`` beta; ``relaxation_time_s`` tau, null = elastic, and
    ``relaxed_ratio`` r = E_inf / E_0, used where the scene's fidelity switches viscoelasticity
    on; ``modulus_kpa`` is then the relaxed modulus E_inf: ``sim.viscoelastic``), the Coulomb
    ``friction`` between tip and surface (0.5 by default, silicone or gel on
    a printed sphere: an oblique contact slips where tan(misalignment) exceeds it; the normal
    force law takes the nearer of the FE's frictionless and full-stick limits:
    ``sim.sample_law.contact_condition``), and ``rigid`` (a rigid reference for calibrating the
    tube's and stage's compliance: the modulus is then not used). How each key reaches the
    world: docs/world.md.

    Surface pose, relative to where the campaign plans the sample (the surface normal against
    the nominal approach): ``tilt_deg`` (angle between the surface normal and the nominal
    approach direction), ``tilt_azimuth_deg`` (about the approach axis, from the direction in
    which the tube's bend angle grows; null: the azimuth at which a roll of the trial's own tube
    meets the tilted surface orthogonally, the placement chooses it and the controller is not
    told), ``curvature_radius_mm`` (a convex sphere of that radius; null = flat) and ``offset_mm``
    (x, y, z in the robot's base frame).

    ``assumed``: what the operator believes (:class:`AssumedConfig`); null = the truth above.

    ``inclusions``: spheres inside the layer (:class:`InclusionConfig`), which the world's
    finite-element tissue feels and the estimator is not told of; ``modulus_kpa`` is then the
    matrix's (docs/inclusions.md).
    """

    name: str
    modulus_kpa: float = field(metadata=limits(gt=0, le=1e6))
    poisson: float = field(default=0.45, metadata=limits(ge=0, le=0.5))
    thickness_mm: float | None = field(default=10.0, metadata=limits(gt=0, le=1000))
    bonded: bool = True
    material: Literal["linear", "neo-hookean"] = "linear"
    lateral_radius_mm: float = field(default=40.0, metadata=limits(gt=0, le=1000))
    relaxation_time_s: float | None = field(default=None, metadata=limits(gt=0, le=1e4))
    relaxed_ratio: float = field(default=1.0, metadata=limits(gt=0, le=1))
    relaxation: Literal["sls", "power-law"] = "sls"
    relaxation_exponent: float = field(default=0.5, metadata=limits(gt=0, le=3))
    friction: float = field(default=0.5, metadata=limits(ge=0, le=5))
    rigid: bool = False
    tilt_deg: float = field(default=0.0, metadata=limits(ge=0, le=80))
    tilt_azimuth_deg: float | None = field(default=0.0, metadata=limits(ge=-360, le=360))
    curvature_radius_mm: float | None = field(default=None, metadata=limits(gt=0, le=1e4))
    offset_mm: tuple[float, float, float] = field(
        default=(0.0, 0.0, 0.0), metadata=limits(ge=-1000, le=1000)
    )
    assumed: AssumedConfig | None = None
    inclusions: tuple[InclusionConfig, ...] = ()

    def validate(self) -> None:
        for k, inc in enumerate(self.inclusions):
            x, y, depth = inc.center_mm
            where = f"inclusions[{k}]"
            if self.rigid:
                raise ValueError(f"{where}: a rigid sample holds no inclusion")
            if self.thickness_mm is not None and depth + inc.radius_mm >= self.thickness_mm:
                raise ValueError(
                    f"{where}: reaches the base (depth {depth:g} + radius {inc.radius_mm:g} mm "
                    f">= thickness_mm {self.thickness_mm:g})"
                )
            if math.hypot(x, y) + inc.radius_mm >= self.lateral_radius_mm:
                raise ValueError(
                    f"{where}: reaches the sample's edge (lateral_radius_mm "
                    f"{self.lateral_radius_mm:g})"
                )

    @property
    def modulus(self) -> float:
        return self.modulus_kpa * KPA

    @property
    def thickness(self) -> float | None:
        return None if self.thickness_mm is None else self.thickness_mm * MM

    @property
    def lateral_radius(self) -> float:
        return self.lateral_radius_mm * MM

    @property
    def tilt(self) -> float:
        return math.radians(self.tilt_deg)

    @property
    def tilt_azimuth(self) -> float | None:
        return None if self.tilt_azimuth_deg is None else math.radians(self.tilt_azimuth_deg)

    @property
    def curvature_radius(self) -> float | None:
        return None if self.curvature_radius_mm is None else self.curvature_radius_mm * MM

    @property
    def offset(self) -> tuple[float, float, float]:
        x, y, z = self.offset_mm
        return (x * MM, y * MM, z * MM)


# Paper Table I: the 11 PDMS / PA-gel phantoms' reference moduli (kPa; its "actual" column, itself
# measured: McKee et al. 2011).
TABLE_I_KPA: tuple[float, ...] = (
    1023.67, 706.30, 504.03, 823.77, 529.33, 908.88, 1122.86, 314.53, 716.74, 499.56, 323.78,
)  # fmt: skip
PAPER_SAMPLES: tuple[SampleConfig, ...] = tuple(
    SampleConfig(name=f"S{i}", modulus_kpa=e) for i, e in enumerate(TABLE_I_KPA, start=1)
)
