"""Sensor design for a tissue modulus range: exposed length, wires, fiber and tip radius.

The paper's sensor buckles at P_cr = 1.35 N (L = 42 mm), which sinks its 3.5 mm sphere 0.5-1.3 mm
into its 300-1100 kPa phantoms (delta/R up to 0.36, past Hertz's range) and would sink it
centimetres into skin (~6 kPa) or brain (~1.8 kPa). The sensor has to be designed for the range.

The method in one line: the beam is a force limiter. It buckles at P_cr = 20.19 EI / L**2 and
the Hertz sphere then stops at the depth where the tissue pushes back as hard,

    delta_b(E) = (3/4 P_cr (1 - nu**2) / (E sqrt(R)))**(2/3),

so over [E_min, E_max] one sensor sees depths in the fixed ratio (E_max / E_min)**(2/3). The
design must fit that ratio between a ceiling (Hertz valid at E_min: delta/R <= 0.1 and a/h <= 0.1
with a = sqrt(R delta)) and a floor (measurable at E_max: delta >= 20 encoder counts). Those
checks need only P_cr and R. Two more need the elastica (``estimation.elastica.fast``), through
the fiber's offset from the neutral axis:

- detection: a short post-buckling shortening e_det (5 % of the smallest delta, the bias that
  detection adds to delta) must bend the gratings well above the pre-buckling norm (the axial
  pre-load P_cr/EA on every grating) plus 6 sigma of FBG noise; a bare fiber (no wires, no
  offset) sees no bending strain and fails here;
- delta bias: the stage travel before detection that is not indentation (axial compression
  P_cr L/EA, e_det, and for a sensor bowed by w0/L the bending shortening while its load rises
  to 0.9 P_cr, c (w0/L)**2 L ((1 - x)**-2 - 1)) stays under 10 % of the smallest delta; the
  detector threshold is raised above the bowed beam's strain at 0.9 P_cr so it does not fire
  early;
- fiber strain: after e_det plus the post-buckling travel the peak fiber strain
  ``(|dy_fbg| + r_fbg) max|dtheta/ds| + P/EA`` stays below the fiber's limit.

Every check is a ratio ``margin`` >= 1 when it holds. The search is a plain grid (fibers x wire
counts x wire diameters x tip radii x exposed lengths, ~1.4e5 candidates, 0.4-1 s), vectorised
over all candidates. Among the feasible ones it picks the most central: the largest worst margin,
then the largest second-worst, and so on (leximin on the logs, rounded to 1 %), so the choice
does not sit on a constraint's edge. When nothing is feasible, the result says why: first a
sensor-independent test (no tip radius fits the depth ratio between ceiling and floor), then the
checks that the closest candidate fails.

Pure functions on floats and numpy arrays; SI units (m, N, Pa).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from estimation.elastica import fast
from estimation.elastica.constants import E_OVER_L_MAX, MODE_SHORTENING, P_CRIT
from estimation.hertz import MAX_CONTACT_RATIO, MAX_DEPTH_RATIO
from estimation.section import Section, composite_section, euler_load

FloatArray = NDArray[np.float64]

MM = 1e-3
UM = 1e-6

CHECKS: dict[str, str] = {
    "hertz_depth": "Hertz small strain at E_min: delta/R <= max_depth_ratio",
    "thickness": "half-space at E_min: contact radius / thickness <= max_contact_ratio",
    "resolution": "measurable at E_max: delta >= resolution_multiple x encoder resolution",
    "detection": "buckling detectable: grating strain norm at e_det >= pre-load norm + noise",
    "delta_bias": "stage travel that is not indentation <= max_bias_fraction x delta at E_max",
    "fiber_strain": "fiber survives: peak strain after e_det + post-buckling travel <= limit",
}
"""The design checks, by name, in the order they are reported."""


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
        max_depth_ratio, max_contact_ratio: Hertz validity limits (``estimation.hertz``).
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
    """

    poisson: float = 0.45
    thickness: float | None = 20 * MM
    encoder_resolution: float = 20 * MM / 4096
    resolution_multiple: float = 20.0
    max_depth_ratio: float = MAX_DEPTH_RATIO
    max_contact_ratio: float = MAX_CONTACT_RATIO
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
            "max_contact_ratio",
            "strain_limit",
            "detection_fraction",
            "max_bias_fraction",
            "grating_length",
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


# -- physics on arrays ---------------------------------------------------------------------------


def hertz_depth(
    force: ArrayLike, modulus: ArrayLike, tip_radius: ArrayLike, nu: float
) -> FloatArray:
    """Depth (m) at which a Hertz sphere of radius ``tip_radius`` carries ``force`` on ``modulus``:
    the inverse of ``estimation.hertz.hertz_force``, (3/4 P (1 - nu**2) / (E sqrt(R)))**(2/3)."""
    P = np.asarray(force, dtype=float)
    E = np.asarray(modulus, dtype=float)
    R = np.asarray(tip_radius, dtype=float)
    if np.any(~np.isfinite(P) | (P < 0)) or np.any(~np.isfinite(E) | (E <= 0)):
        raise ValueError("hertz_depth: force must be >= 0 and modulus > 0 (finite)")
    if np.any(~np.isfinite(R) | (R <= 0)):
        raise ValueError("hertz_depth: tip_radius must be finite and > 0")
    return np.asarray((0.75 * P * (1.0 - nu**2) / (E * np.sqrt(R))) ** (2.0 / 3.0))


@dataclass(frozen=True)
class _Arrays:
    """Everything ``_assess`` computes, one entry per candidate."""

    p_cr: FloatArray
    delta_soft: FloatArray
    delta_stiff: FloatArray
    depth_ratio: FloatArray
    contact_ratio: FloatArray
    detection: FloatArray
    floor: FloatArray
    early: FloatArray
    bias: FloatArray
    peak: FloatArray
    checks: dict[str, tuple[FloatArray, FloatArray, bool]]

    def log_margins(self) -> FloatArray:
        """(N, C) natural logs of the margins, columns in ``checks`` order."""
        cols = []
        for value, limit, upper in self.checks.values():
            with np.errstate(divide="ignore"):
                ratio = np.log(limit) - np.log(value) if upper else np.log(value) - np.log(limit)
            cols.append(np.where(np.isnan(ratio), -np.inf, ratio))
        return np.stack(cols, axis=-1)


def _grating_strains(
    e_over_L: FloatArray, fiber_offset: FloatArray, L: FloatArray, c: DesignConstraints
) -> FloatArray:
    """(N, G) bending strains of the gratings at geometric shortening ``e_over_L`` (N,)."""
    sol = fast.solve(np.minimum(e_over_L, E_OVER_L_MAX)[:, None])
    centres = np.asarray(c.grating_centres_from_tip)[None, :]
    half = 0.5 * c.grating_length
    s0 = (L[:, None] - centres - half) / L[:, None]
    s1 = (L[:, None] - centres + half) / L[:, None]
    return np.asarray(fiber_offset[:, None] * sol.mean_curvature(s0, s1) / L[:, None])


def imperfection_state(w0_over_L: float, load_fraction: float) -> tuple[float, float]:
    """A beam bowed by ``w0_over_L`` in its first mode, loaded to ``load_fraction`` P_cr.

    Linear theory amplifies the bow to A = w0 / (1 - x). Returns (e_equiv/L, e_imp/L):
    the shortening of the perfect elastica with the same pin reaction (the same bending, for the
    grating strains), c ((A - w0)/L)**2, and the bending shortening the stage has travelled to
    get there, c ((A/L)**2 - (w0/L)**2), with c = ``MODE_SHORTENING`` (the elastica's onset
    slope |r| / sqrt(e/L) is MODE_REACTION / sqrt(c)).
    """
    x = load_fraction
    amplitude = w0_over_L * x / (1.0 - x)  # (A - w0) / L
    e_equiv = MODE_SHORTENING * amplitude**2
    e_imp = MODE_SHORTENING * w0_over_L**2 * ((1.0 - x) ** -2 - 1.0)
    return e_equiv, e_imp


def _peak_curvature(e_over_L: FloatArray) -> FloatArray:
    """max over the beam of |L dtheta/ds|: 2 k t where u0 + t s crosses 0 (cn = 1) inside the
    beam, i.e. when u0 <= 0, else at the clamp |2 k t cn(u0)| (cn(K) = 0 at the pin)."""
    sol = fast.solve(np.minimum(e_over_L, E_OVER_L_MAX))
    full = 2.0 * sol.modulus * sol.wavenumber
    return np.asarray(np.where(sol.u0 <= 0.0, full, np.abs(sol.curvature(0.0))))


def _assess(
    EI: FloatArray,
    EA: FloatArray,
    fiber_offset: FloatArray,
    fiber_radius: FloatArray,
    R: FloatArray,
    L: FloatArray,
    modulus_range: tuple[float, float],
    c: DesignConstraints,
) -> _Arrays:
    """All checks for N candidates (1-D arrays of length N); L must reach past the gratings."""
    e_min, e_max = modulus_range
    p_cr = P_CRIT * EI / L**2
    preload = p_cr / EA
    d_soft = hertz_depth(p_cr, e_min, R, c.poisson)
    d_stiff = hertz_depth(p_cr, e_max, R, c.poisson)
    depth_ratio = d_soft / R
    h = math.inf if c.thickness is None else c.thickness
    contact_ratio = np.sqrt(R * d_soft) / h
    e_det = c.detection_fraction * d_stiff
    bending = _grating_strains(e_det / L, fiber_offset, L, c)
    # the beam may buckle to either side; the pre-load adds to one and cancels on the other
    detection = np.minimum(
        np.linalg.norm(bending - preload[:, None], axis=1),
        np.linalg.norm(bending + preload[:, None], axis=1),
    )
    n_gratings = len(c.grating_centres_from_tip)
    floor = math.sqrt(n_gratings) * preload + c.noise_sigmas * c.strain_noise
    g_imp, e_imp = imperfection_state(c.imperfection, c.detect_load_fraction)
    early = np.zeros_like(L)
    if c.imperfection > 0:
        bow = _grating_strains(np.full_like(L, g_imp), fiber_offset, L, c)
        load = c.detect_load_fraction * preload[:, None]
        early = np.maximum(np.linalg.norm(bow - load, axis=1), np.linalg.norm(bow + load, axis=1))
    g_end = (e_det + c.post_buckling_travel) / L
    peak = (np.abs(fiber_offset) + fiber_radius) * _peak_curvature(g_end) / L + preload
    peak = np.where(g_end > E_OVER_L_MAX, np.inf, peak)
    min_delta = c.resolution_multiple * c.encoder_resolution
    checks: dict[str, tuple[FloatArray, FloatArray, bool]] = {
        "hertz_depth": (depth_ratio, np.full_like(L, c.max_depth_ratio), True),
    }
    if c.thickness is not None:
        checks["thickness"] = (contact_ratio, np.full_like(L, c.max_contact_ratio), True)
    checks["resolution"] = (d_stiff, np.full_like(L, min_delta), False)
    checks["detection"] = (detection, floor, False)
    bias = p_cr * L / EA + e_det + e_imp * L
    checks["delta_bias"] = (bias, c.max_bias_fraction * d_stiff, True)
    checks["fiber_strain"] = (peak, np.full_like(L, c.strain_limit), True)
    return _Arrays(
        p_cr=p_cr,
        delta_soft=d_soft,
        delta_stiff=d_stiff,
        depth_ratio=depth_ratio,
        contact_ratio=contact_ratio if c.thickness is not None else np.full_like(L, math.nan),
        detection=detection,
        floor=floor,
        early=early,
        bias=bias,
        peak=peak,
        checks=checks,
    )


def _checked_range(modulus_range: tuple[float, float]) -> tuple[float, float]:
    lo, hi = (float(v) for v in modulus_range)
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo <= hi):
        raise ValueError(f"modulus range must be 0 < E_min <= E_max (Pa), got {modulus_range!r}")
    return lo, hi


def _evaluation(
    design: SensorDesign, a: _Arrays, i: int, rng: tuple[float, float]
) -> DesignEvaluation:
    checks = tuple(
        Check(name, float(value[i]), float(limit[i]), upper)
        for name, (value, limit, upper) in a.checks.items()
    )
    detect, floor, early = float(a.detection[i]), float(a.floor[i]), float(a.early[i])
    threshold = max(math.sqrt(detect * floor), early) if detect > floor else None
    return DesignEvaluation(
        design=design,
        modulus_range=rng,
        critical_load=float(a.p_cr[i]),
        delta_soft=float(a.delta_soft[i]),
        delta_stiff=float(a.delta_stiff[i]),
        depth_ratio=float(a.depth_ratio[i]),
        contact_ratio=float(a.contact_ratio[i]),
        detection_strain=detect,
        detection_floor=floor,
        bow_strain=early,
        threshold=threshold,
        delta_bias=float(a.bias[i]),
        peak_strain=float(a.peak[i]),
        checks=checks,
    )


def evaluate_design(
    design: SensorDesign,
    modulus_range: tuple[float, float],
    constraints: DesignConstraints | None = None,
) -> DesignEvaluation:
    """Predicted indentations at buckling and every check for one sensor on a modulus range.

    Raises:
        ValueError: a non-physical range or sensor, or gratings not all on the exposed beam.
    """
    c = constraints or DesignConstraints()
    rng = _checked_range(modulus_range)
    if not design.exposed_length >= c.grating_reach:
        raise ValueError(
            f"exposed length {design.exposed_length * 1e3:.3g} mm leaves gratings inside the "
            f"tube: they reach {c.grating_reach * 1e3:.3g} mm from the tip"
        )
    section = design.section()

    def one(x: float) -> FloatArray:
        return np.array([x], dtype=np.float64)

    arrays = _assess(
        one(section.EI),
        one(section.EA),
        one(section.fiber_offset),
        one(design.fiber_radius),
        one(design.tip_radius),
        one(design.exposed_length),
        rng,
        c,
    )
    return _evaluation(design, arrays, 0, rng)


# -- the search ----------------------------------------------------------------------------------


def _hardware(space: DesignSpace) -> list[tuple[float, int, float]]:
    """(fiber radius, wire count, wire radius) combinations; one bare fiber per fiber radius."""
    smallest = min(space.wire_diameters) / 2
    out: list[tuple[float, int, float]] = []
    for r_f in space.fiber_radii:
        for n in sorted(set(space.wire_counts)):
            radii = [smallest] if n == 0 else [d / 2 for d in space.wire_diameters]
            out.extend((r_f, int(n), r_w) for r_w in radii)
    return out


def _leximin(log_margins: FloatArray, rows: NDArray[np.intp]) -> int:
    """Row of ``rows`` whose sorted margins are lexicographically largest (1 % rounding)."""
    sub = np.sort(log_margins[rows], axis=1)
    keys = np.round(np.where(np.isfinite(sub), sub, np.sign(sub) * 1e6), 2)
    order = np.lexsort(tuple(-keys[:, j] for j in reversed(range(keys.shape[1]))))
    return int(rows[order[0]])


def _depth_window(rng: tuple[float, float], space: DesignSpace, c: DesignConstraints) -> str | None:
    """Why no sensor at all can work, if that is the case: the ceiling/floor ratio test."""
    floor = c.resolution_multiple * c.encoder_resolution
    need = (rng[1] / rng[0]) ** (2.0 / 3.0)
    best_ratio, best_r, best_ceiling = 0.0, 0.0, 0.0
    for R in space.tip_radii:
        ceiling = c.max_depth_ratio * R
        if c.thickness is not None:
            ceiling = min(ceiling, (c.max_contact_ratio * c.thickness) ** 2 / R)
        if ceiling / floor > best_ratio:
            best_ratio, best_r, best_ceiling = ceiling / floor, R, ceiling
    if best_ratio >= need:
        return None
    where = "" if c.thickness is None else f" on a {c.thickness * 1e3:g} mm layer"
    return (
        f"the modulus range is too wide for any sensor{where}: one sensor's indentation at "
        f"buckling scales as E**(-2/3), so E_max/E_min = {rng[1] / rng[0]:.3g} needs a depth "
        f"ratio of {need:.3g}, but Hertz validity (delta/R <= {c.max_depth_ratio:g}"
        + ("" if c.thickness is None else f", a/h <= {c.max_contact_ratio:g}")
        + f") caps delta at {best_ceiling * 1e3:.3g} mm (best tip R = {best_r * 1e3:g} mm) and "
        f"the encoder needs delta >= {c.resolution_multiple:g} x "
        f"{c.encoder_resolution * 1e6:.3g} um = {floor * 1e3:.3g} mm: a ratio of "
        f"{best_ratio:.3g} at most. Narrow the range, or relax the limits (thicker sample, "
        f"finer encoder, fewer counts)."
    )


def _window(ok: NDArray[np.bool_], lengths: FloatArray, i: int) -> tuple[float, float]:
    lo = hi = i
    while lo > 0 and ok[lo - 1]:
        lo -= 1
    while hi < len(ok) - 1 and ok[hi + 1]:
        hi += 1
    return float(lengths[lo]), float(lengths[hi])


def _describe(ev: DesignEvaluation) -> str:
    d = ev.design
    wires = "bare fiber" if d.wire_count == 0 else f"{d.wire_count} x {d.wire_radius * 2e6:.0f} um"
    return (
        f"fiber r = {d.fiber_radius * 1e6:.1f} um, {wires} NiTi, tip R = {d.tip_radius * 1e3:g} "
        f"mm, L = {d.exposed_length * 1e3:.1f} mm (P_cr = {ev.critical_load * 1e3:.3g} mN)"
    )


def _fail_text(ch: Check) -> str:
    op = ">" if ch.upper else "<"
    return f"{ch.name} ({ch.description}): {ch.value:.3g} {op} {ch.limit:.3g}"


def design_sensor(
    modulus_range: tuple[float, float],
    constraints: DesignConstraints | None = None,
    space: DesignSpace | None = None,
) -> DesignResult:
    """Propose fiber, wires, tip radius and exposed length for tissue in ``modulus_range`` (Pa).

    Returns:
        A :class:`DesignResult`: the most central feasible design with its evaluation and the
        window of exposed lengths over which that hardware passes, or ``success`` False with a
        message naming the failing constraint (and the closest candidate's evaluation).

    Raises:
        ValueError: a non-physical range, constraint or design space.
    """
    c = constraints or DesignConstraints()
    sp = space or DesignSpace()
    rng = _checked_range(modulus_range)
    lengths = sp.lengths()
    lengths = lengths[lengths >= c.grating_reach]
    if lengths.size == 0:
        return DesignResult(
            False,
            f"no exposed length in the design space reaches past the gratings "
            f"({c.grating_reach * 1e3:.3g} mm from the tip)",
            None,
            None,
            0,
            0,
        )
    hardware = _hardware(sp)
    sections = [
        composite_section(r_f, sp.fiber_modulus, r_w, sp.wire_modulus, n)
        for r_f, n, r_w in hardware
    ]
    tips = np.asarray(sp.tip_radii, dtype=np.float64)
    n_h, n_t, n_l = len(hardware), tips.size, lengths.size
    hi, ti, li = (x.ravel() for x in np.indices((n_h, n_t, n_l)))

    def per_section(attr: str) -> FloatArray:
        values = np.asarray([getattr(s, attr) for s in sections], dtype=np.float64)
        return np.asarray(values[hi], dtype=np.float64)

    arrays = _assess(
        per_section("EI"),
        per_section("EA"),
        per_section("fiber_offset"),
        np.asarray([h[0] for h in hardware], dtype=np.float64)[hi],
        tips[ti],
        lengths[li],
        rng,
        c,
    )
    logm = arrays.log_margins()
    ok = np.all(logm >= 0.0, axis=1)
    failures = {name: int(np.sum(logm[:, j] < 0.0)) for j, name in enumerate(arrays.checks)}
    feasible = np.flatnonzero(ok)
    best = _leximin(logm, feasible if feasible.size else np.arange(ok.size))
    r_f, n, r_w = hardware[int(hi[best])]
    design = SensorDesign(
        fiber_radius=r_f,
        fiber_modulus=sp.fiber_modulus,
        wire_count=n,
        wire_radius=r_w,
        wire_modulus=sp.wire_modulus,
        tip_radius=float(tips[ti[best]]),
        exposed_length=float(lengths[li[best]]),
    )
    ev = _evaluation(design, arrays, best, rng)
    if feasible.size:
        same = (hi == hi[best]) & (ti == ti[best])
        window = _window(ok[same], lengths, int(li[best]))
        return DesignResult(
            True,
            f"{feasible.size} of {ok.size} candidates pass every check; most central: "
            f"{_describe(ev)}; worst margin {ev.worst.margin:.2f} ({ev.worst.name})",
            ev,
            window,
            int(ok.size),
            int(feasible.size),
            failures,
        )
    reason = _depth_window(rng, sp, c)
    closest = "; ".join(_fail_text(ch) for ch in ev.failed)
    closest = f"the closest candidate ({_describe(ev)}) fails {closest}."
    message = "no design satisfies the constraints: " + (
        f"{reason} {closest[0].upper()}{closest[1:]}" if reason else closest
    )
    return DesignResult(False, message, ev, None, int(ok.size), 0, failures)


__all__ = [
    "CHECKS",
    "Check",
    "DesignConstraints",
    "DesignEvaluation",
    "DesignResult",
    "DesignSpace",
    "SensorDesign",
    "design_sensor",
    "evaluate_design",
    "hertz_depth",
]
