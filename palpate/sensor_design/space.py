"""What a design is drawn from and must respect: the design space, the constraints, a sensor.

Plain, checked data (SI units): :class:`DesignSpace` (the grid the search runs over),
:class:`DesignConstraints` (the tissue and the limits), :class:`SensorDesign` (one candidate).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..estimation.beam.section import Section, across_rigidity, composite_section, euler_load
from ..estimation.contact.law import LAYER_STRAIN_MAX
from .weight import SAG_LIMIT, TIP_DENSITY, linear_mass

FloatArray = NDArray[np.float64]

MM = 1e-3
UM = 1e-6


@dataclass(frozen=True)
class DesignSpace:
    """What can be built: the grid the search runs over (SI units).

    Attributes:
        fiber_radii: FBG fiber radii (m): 40 um (80 um reduced-cladding fibers), 62.5 um
            (standard 125 um cladding) and the paper's 115 um (coated).
        fiber_modulus: silica, Pa.
        wire_modulus: NiTi, Pa.
        wire_diameters: manufacturable NiTi wire diameters (m).
        wire_counts: wires in the row under the fiber (0 = a bare fiber).
        tip_radii: radii (m) of the printed tip spheres.
        length_range: (min, max) exposed length (m).
        length_step: grid step of the exposed length (m).
    """

    fiber_radii: tuple[float, ...] = (40 * UM, 62.5 * UM, 115 * UM)
    fiber_modulus: float = 67e9
    wire_modulus: float = 55e9
    wire_diameters: tuple[float, ...] = (25 * UM, 50 * UM, 75 * UM, 100 * UM, 150 * UM, 200 * UM)
    wire_counts: tuple[int, ...] = (0, 1, 2, 3, 4)
    tip_radii: tuple[float, ...] = tuple(
        r * MM for r in (0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0, 5.0, 6.0, 7.0, 8.0, 10.0)
    )
    length_range: tuple[float, float] = (20 * MM, 100 * MM)
    length_step: float = 0.5 * MM

    def __post_init__(self) -> None:
        for name in ("fiber_radii", "wire_diameters", "tip_radii"):
            values = getattr(self, name)
            if not values or not all(math.isfinite(v) and v > 0 for v in values):
                raise ValueError(f"{name} must be a non-empty list of lengths > 0, got {values!r}")
        if not self.wire_counts or any(
            isinstance(n, bool) or int(n) != n or n < 0 for n in self.wire_counts
        ):
            raise ValueError(f"wire_counts must be integers >= 0, got {self.wire_counts!r}")
        lo, hi = self.length_range
        if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo <= hi):
            raise ValueError(f"length_range must be 0 < min <= max, got {self.length_range!r}")
        if not self.length_step > 0:
            raise ValueError(f"length_step must be > 0, got {self.length_step!r}")
        for name in ("fiber_modulus", "wire_modulus"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name} must be > 0 Pa")

    def lengths(self) -> FloatArray:
        lo, hi = self.length_range
        n = math.floor((hi - lo) / self.length_step + 1e-9) + 1
        return np.asarray(lo + self.length_step * np.arange(n), dtype=np.float64)


@dataclass(frozen=True)
class DesignConstraints:
    """The tissue and the limits a design must respect (SI units).

    Attributes:
        poisson: the tissue's Poisson ratio.
        thickness: tissue layer thickness h (m); None for a half-space (no a/h check).
        encoder_resolution: stage travel per encoder count (m): lead / 4096 for the lead screw.
        resolution_multiple: the smallest indentation, in encoder counts.
        max_depth_ratio: the deepest sphere indentation delta/R the estimate should rely on:
            DESIGN_DEPTH_RATIO, where the exact law's finite-strain bound reaches 5 %
            (``estimation.jointfit.modelform``; the law's tables reach delta/R = 1).
        max_layer_strain: the layer's trusted compression delta/h (the exact layer law's
            domain, ``estimation.contact.law.LAYER_STRAIN_MAX``; it also keeps chi =
            sqrt(R delta)/h within the law's 3 for any R < 45 h).
        strain_limit: the fiber's strain limit (dimensionless).
        strain_noise: FBG strain noise per grating, 1 sigma (dimensionless): sigma_pm / k'_eps.
        noise_sigmas: detection floor above the pre-load, in units of ``strain_noise``.
        detection_fraction: post-buckling shortening at which buckling must be detectable, as a
            fraction of the smallest indentation (it adds to the measured delta).
        imperfection: initial bow w0/L of the sensor (0 = straight). A bowed beam bends before
            P_cr; the detector must wait until ``detect_load_fraction`` P_cr, and the bending
            shortening until then adds to the measured delta.
        detect_load_fraction: the load, as a fraction of P_cr, below which the imperfect beam's
            bending must stay under the detection threshold.
        max_bias_fraction: the largest stage travel that is not indentation (axial compression
            P_cr L/EA, detection shortening, imperfection shortening), as a fraction of the
            smallest indentation.
        post_buckling_travel: stage travel after detection (m), for the fiber-strain check.
        grating_centres_from_tip: distances (m) from the sensor tip to the used gratings.
        grating_length: grating length (m).
        plane_margin: how much stiffer across the fiber's plane than in it the beam must be, so
            that it buckles in the plane the gratings see (a beam buckles about its softest
            axis): 2 keeps a bow across within twice its size at P_cr (1 / (1 - 1/2)); the
            paper's sensor has 3.2.
        tip_force_resolution: the tip grating's load resolution (N, 1 sigma), or None for a
            sensor without one (no ``force`` check). With it, P_cr must be large enough that
            the load at which the contact is seen, ``contact_sigmas`` resolutions, sinks the
            Hertz sphere at most ``contact_depth_fraction`` of its depth at buckling (the load
            grows as delta**1.5, whatever E): :attr:`smallest_critical_load`.
        contact_sigmas: the contact threshold in load resolutions (``campaign.contact: tip``
            takes the contact at 5 sigma).
        contact_depth_fraction: the share of the indentation at buckling the contact's
            threshold may take (the rest is the load curve the fit reads).
        held_across: the sensor must carry its own weight in any pose (``weight`` check: held
            across, the tip's sag under a solid printed sphere of ``tip_density`` and the beam
            stays within ``sag_limit`` of L; ``design.weight``). False: it is only
            reported after the search (usable pointing vertically).
        tip_density: the tip sphere's density (kg/m^3) for the ``weight`` check.
        sag_limit: the sag / L the ``weight`` check allows.
    """

    poisson: float = 0.45
    thickness: float | None = 20 * MM
    encoder_resolution: float = 20 * MM / 4096
    resolution_multiple: float = 20.0
    max_depth_ratio: float = 0.5
    max_layer_strain: float = LAYER_STRAIN_MAX
    strain_limit: float = 5e-3
    strain_noise: float = 1.0 / 0.424 * 1e-6
    noise_sigmas: float = 6.0
    detection_fraction: float = 0.05
    imperfection: float = 0.0
    detect_load_fraction: float = 0.9
    max_bias_fraction: float = 0.1
    post_buckling_travel: float = 0.3 * MM
    grating_centres_from_tip: tuple[float, ...] = (10 * MM, 18 * MM, 26 * MM)
    grating_length: float = 3 * MM
    plane_margin: float = 2.0
    tip_force_resolution: float | None = None
    contact_sigmas: float = 5.0
    contact_depth_fraction: float = 0.5
    held_across: bool = False
    tip_density: float = TIP_DENSITY
    sag_limit: float = SAG_LIMIT

    def __post_init__(self) -> None:
        if not 0.0 <= self.poisson < 0.5 + 1e-12:
            raise ValueError(f"poisson must be in [0, 0.5], got {self.poisson!r}")
        if self.thickness is not None and not (
            math.isfinite(self.thickness) and self.thickness > 0
        ):
            raise ValueError(f"thickness must be > 0 m or None, got {self.thickness!r}")
        positive = (
            "encoder_resolution",
            "resolution_multiple",
            "max_depth_ratio",
            "max_layer_strain",
            "strain_limit",
            "detection_fraction",
            "max_bias_fraction",
            "grating_length",
            "plane_margin",
            "contact_sigmas",
            "contact_depth_fraction",
            "tip_density",
            "sag_limit",
        )
        for name in positive:
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be finite and > 0, got {value!r}")
        for name in ("strain_noise", "noise_sigmas", "post_buckling_travel"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise ValueError(f"{name} must be finite and >= 0, got {value!r}")
        if not 0.0 <= self.imperfection < 0.1:
            raise ValueError(f"imperfection w0/L must be in [0, 0.1), got {self.imperfection!r}")
        if not 0.0 < self.detect_load_fraction < 1.0:
            raise ValueError(
                f"detect_load_fraction must be in (0, 1), got {self.detect_load_fraction!r}"
            )
        if not self.grating_centres_from_tip or min(self.grating_centres_from_tip) < 0:
            raise ValueError("grating_centres_from_tip must list distances >= 0")
        res = self.tip_force_resolution
        if res is not None and not (math.isfinite(res) and res > 0):
            raise ValueError(f"tip_force_resolution must be > 0 N or None, got {res!r}")
        if self.contact_depth_fraction > 1:
            raise ValueError("contact_depth_fraction must be in (0, 1]")

    @property
    def smallest_critical_load(self) -> float:
        """The smallest P_cr (N) the tip grating's resolution allows (0 without a grating)."""
        if self.tip_force_resolution is None:
            return 0.0
        return float(
            self.contact_sigmas * self.tip_force_resolution / self.contact_depth_fraction**1.5
        )

    @property
    def grating_reach(self) -> float:
        """Distance (m) from the tip to the far end of the farthest grating: the shortest L."""
        return max(self.grating_centres_from_tip) + 0.5 * self.grating_length


@dataclass(frozen=True)
class SensorDesign:
    """A sensor: fiber on ``wire_count`` wires, a tip sphere, an exposed length (SI units)."""

    fiber_radius: float
    fiber_modulus: float
    wire_count: int
    wire_radius: float
    wire_modulus: float
    tip_radius: float
    exposed_length: float

    def section(self) -> Section:
        return composite_section(
            self.fiber_radius,
            self.fiber_modulus,
            self.wire_radius,
            self.wire_modulus,
            self.wire_count,
        )

    def critical_load(self) -> float:
        return euler_load(self.section().EI, self.exposed_length)

    def linear_mass(self) -> float:
        """The beam's mass per length (kg/m)."""
        return linear_mass(self.fiber_radius, self.wire_count, self.wire_radius)

    def across_rigidity(self) -> float:
        """EI across the fiber's plane (N m^2), :func:`estimation.beam.section.across_rigidity`."""
        return across_rigidity(
            self.fiber_radius,
            self.fiber_modulus,
            self.wire_radius,
            self.wire_modulus,
            self.wire_count,
        )
