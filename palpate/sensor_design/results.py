"""What the design tools return: the checks by name, one check's margin, a sensor's
evaluation on a modulus range, and the search's result."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from .space import SensorDesign

CHECKS: dict[str, str] = {
    "depth": "the estimator's trusted sphere depth at E_min: delta/R <= max_depth_ratio",
    "thickness": "the layer's trusted compression at E_min: delta/h <= max_layer_strain",
    "resolution": "measurable at E_max: delta >= resolution_multiple x encoder resolution",
    "detection": "buckling detectable: grating strain norm at e_det >= pre-load norm + noise",
    "delta_bias": "stage travel that is not indentation <= max_bias_fraction x delta at E_max",
    "fiber_strain": "fiber survives: peak strain after e_det + post-buckling travel <= limit",
    "plane": "buckles in the fiber's plane: EI across it >= plane_margin x EI in it",
    "weight": "carries its own weight held across: the tip's sag (a solid printed sphere and "
    "the beam) <= sag_limit x L",
    "force": "the tip grating resolves the load curve: the contact's load (contact_sigmas x "
    "resolution) sinks the tip at most contact_depth_fraction of delta at buckling",
}
"""The design checks, by name, in the order they are reported."""


@dataclass(frozen=True)
class Check:
    """One design check: ``value`` against ``limit``; ``upper`` means value must be <= limit."""

    name: str
    value: float
    limit: float
    upper: bool

    @property
    def margin(self) -> float:
        """limit/value (upper bound) or value/limit (lower bound): >= 1 when the check holds."""
        if self.upper:
            return self.limit / self.value if self.value > 0 else math.inf
        return self.value / self.limit if self.limit > 0 else math.inf

    @property
    def ok(self) -> bool:
        return self.margin >= 1.0

    @property
    def description(self) -> str:
        return CHECKS[self.name]


@dataclass(frozen=True)
class DesignEvaluation:
    """What a sensor does on a modulus range (SI units).

    Attributes:
        design: the sensor.
        modulus_range: (E_min, E_max), Pa.
        critical_load: P_cr (N).
        delta_soft, delta_stiff: indentation at buckling at E_min and at E_max (m).
        depth_ratio: delta/R at E_min.
        contact_ratio: a/h at E_min (NaN for a half-space).
        detection_strain: grating strain norm at the detection shortening e_det.
        detection_floor: pre-load norm + noise_sigmas x noise (strain).
        bow_strain: grating strain norm of the bowed beam at detect_load_fraction P_cr (0 for a
            straight one): the threshold must stay above it.
        threshold: suggested norm threshold for the paper's detector: sqrt(floor x detection),
            raised to the bowed beam's strain at detect_load_fraction P_cr; None when buckling is
            not detectable.
        delta_bias: stage travel before detection that is not indentation (m): axial compression
            P_cr L / EA + detection shortening e_det + the bow's bending shortening.
        peak_strain: peak fiber strain after e_det + post-buckling travel.
        checks: the checks in ``CHECKS`` order (``thickness`` left out for a half-space).
    """

    design: SensorDesign
    modulus_range: tuple[float, float]
    critical_load: float
    delta_soft: float
    delta_stiff: float
    depth_ratio: float
    contact_ratio: float
    detection_strain: float
    detection_floor: float
    bow_strain: float
    threshold: float | None
    delta_bias: float
    peak_strain: float
    checks: tuple[Check, ...]

    @property
    def ok(self) -> bool:
        return all(c.ok for c in self.checks)

    @property
    def failed(self) -> tuple[Check, ...]:
        return tuple(c for c in self.checks if not c.ok)

    @property
    def worst(self) -> Check:
        return min(self.checks, key=lambda c: c.margin)


@dataclass(frozen=True)
class DesignResult:
    """The proposal, or why there is none.

    Attributes:
        success: a design satisfies every check.
        message: what was chosen, or which constraint fails and by how much.
        evaluation: the chosen design's evaluation; when ``success`` is False, the closest
            candidate's (largest worst margin), None if no candidate could be evaluated.
        length_window: (min, max) exposed length (m) over which the chosen hardware passes every
            check (on the search grid); None without a design.
        candidates: candidates evaluated.
        feasible: how many passed every check.
        failures: per check, how many candidates failed it.
    """

    success: bool
    message: str
    evaluation: DesignEvaluation | None
    length_window: tuple[float, float] | None
    candidates: int
    feasible: int
    failures: dict[str, int] = field(default_factory=dict)

    @property
    def design(self) -> SensorDesign | None:
        return self.evaluation.design if self.success and self.evaluation else None
