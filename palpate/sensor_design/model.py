"""The physical model of a candidate sensor on a modulus range, vectorised over candidates.

For N candidates (1-D arrays of EI, EA, fiber offset and radius, tip radius R, exposed length L):
the critical load P_cr = 20.19 EI / L**2 and the Hertz depths it sinks the tip to at E_min and
E_max (:func:`hertz_depth`); the grating strains at the detection shortening from the elastica
(``estimation.beam.elastica.fast``); the bowed beam's strain before P_cr and its bending shortening
(:func:`imperfection_state`); the peak fiber strain after the post-buckling travel; and every
check of ``results.CHECKS`` as (value, limit, upper). See ``design`` for the
reasoning behind each check.

Cost: two or three vectorised elastica evaluations (``fast.solve``) for all candidates at once:
the search assesses ~1.4e5 candidates in one call.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..estimation.beam.elastica import fast
from ..estimation.beam.elastica.constants import E_OVER_L_MAX, MODE_SHORTENING, P_CRIT
from .results import Check, DesignEvaluation
from .space import DesignConstraints, SensorDesign
from .weight import sag_share

FloatArray = NDArray[np.float64]


def hertz_depth(
    force: ArrayLike, modulus: ArrayLike, tip_radius: ArrayLike, nu: float
) -> FloatArray:
    """Depth (m) at which a Hertz sphere of radius ``tip_radius`` carries ``force`` on ``modulus``:
    the inverse of ``estimation.contact.hertz.hertz_force``, (3/4 P (1 - nu**2) / (E
    sqrt(R)))**(2/3)."""
    P = np.asarray(force, dtype=float)
    E = np.asarray(modulus, dtype=float)
    R = np.asarray(tip_radius, dtype=float)
    if np.any(~np.isfinite(P) | (P < 0)) or np.any(~np.isfinite(E) | (E <= 0)):
        raise ValueError("hertz_depth: force must be >= 0 and modulus > 0 (finite)")
    if np.any(~np.isfinite(R) | (R <= 0)):
        raise ValueError("hertz_depth: tip_radius must be finite and > 0")
    return np.asarray((0.75 * P * (1.0 - nu**2) / (E * np.sqrt(R))) ** (2.0 / 3.0))


@dataclass(frozen=True, eq=False)
class Assessment:
    """Everything :func:`assess` computes, one (N,) entry per candidate (SI units); the fields
    are those of ``results.DesignEvaluation`` (``early`` is its ``bow_strain``, ``floor`` its
    ``detection_floor``, ``bias`` its ``delta_bias``, ``peak`` its ``peak_strain``), and
    ``checks`` maps each check's name to (value, limit, upper)."""

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


def assess(
    EI: FloatArray,
    EI_across: FloatArray,
    EA: FloatArray,
    fiber_offset: FloatArray,
    fiber_radius: FloatArray,
    R: FloatArray,
    L: FloatArray,
    modulus_range: tuple[float, float],
    c: DesignConstraints,
    linear_mass: FloatArray | None = None,
) -> Assessment:
    """All checks for N candidates: EI in the fiber's plane and across it (N m^2), EA (N),
    fiber offset and radius, tip radius R and exposed length L (m), each (N,); L must reach
    past the gratings. ``linear_mass`` (kg/m, (N,)) is the beam's, for the ``weight`` check
    (``c.held_across``; required then)."""
    e_min, e_max = modulus_range
    p_cr = P_CRIT * EI / L**2
    preload = p_cr / EA  # the axial strain every grating carries at P_cr
    d_soft = hertz_depth(p_cr, e_min, R, c.poisson)
    d_stiff = hertz_depth(p_cr, e_max, R, c.poisson)
    depth_ratio = d_soft / R
    contact_ratio = _contact_ratio(R, d_soft, c)
    e_det = c.detection_fraction * d_stiff
    detection = _detection_strain(e_det, preload, fiber_offset, L, c)
    floor = math.sqrt(len(c.grating_centres_from_tip)) * preload + c.noise_sigmas * c.strain_noise
    early = _bow_strain(preload, fiber_offset, L, c)
    peak = _peak_strain(e_det, preload, fiber_offset, fiber_radius, L, c)
    _, e_imp = imperfection_state(c.imperfection, c.detect_load_fraction)
    bias = p_cr * L / EA + e_det + e_imp * L
    checks = _checks(depth_ratio, contact_ratio, d_stiff, detection, floor, bias, peak, c)
    checks["plane"] = (EI_across / EI, np.full_like(EI, c.plane_margin), False)
    if c.held_across:
        if linear_mass is None:
            raise ValueError("the weight check (held_across) needs the beam's linear mass")
        tip_mass = c.tip_density * 4.0 / 3.0 * math.pi * R**3
        sag = sag_share(tip_mass, linear_mass, EI, L)
        checks["weight"] = (sag, np.full_like(EI, c.sag_limit), True)
    if c.tip_force_resolution is not None:
        checks["force"] = (p_cr, np.full_like(EI, c.smallest_critical_load), False)
    return Assessment(
        p_cr,
        d_soft,
        d_stiff,
        depth_ratio,
        contact_ratio,
        detection,
        floor,
        early,
        bias,
        peak,
        checks,
    )


def _contact_ratio(R: FloatArray, delta_soft: FloatArray, c: DesignConstraints) -> FloatArray:
    """(N,) the layer's compression delta/h at E_min; NaN for a half-space."""
    if c.thickness is None:
        return np.full_like(R, math.nan)
    return np.asarray(delta_soft / c.thickness + 0.0 * R)


def _detection_strain(
    e_det: FloatArray,
    preload: FloatArray,
    fiber_offset: FloatArray,
    L: FloatArray,
    c: DesignConstraints,
) -> FloatArray:
    """(N,) grating strain norm at the detection shortening ``e_det`` (m). The beam may buckle
    to either side; the pre-load adds to the bending on one and cancels on the other: the
    smaller norm counts."""
    bending = _grating_strains(e_det / L, fiber_offset, L, c)
    return np.asarray(
        np.minimum(
            np.linalg.norm(bending - preload[:, None], axis=1),
            np.linalg.norm(bending + preload[:, None], axis=1),
        )
    )


def _bow_strain(
    preload: FloatArray, fiber_offset: FloatArray, L: FloatArray, c: DesignConstraints
) -> FloatArray:
    """(N,) grating strain norm of the bowed beam at ``detect_load_fraction`` P_cr, on the side
    where the pre-load adds (0 for a straight beam): the detector's threshold must stay above."""
    early = np.zeros_like(L)
    if c.imperfection > 0:
        g_imp, _ = imperfection_state(c.imperfection, c.detect_load_fraction)
        bow = _grating_strains(np.full_like(L, g_imp), fiber_offset, L, c)
        load = c.detect_load_fraction * preload[:, None]
        early = np.maximum(np.linalg.norm(bow - load, axis=1), np.linalg.norm(bow + load, axis=1))
    return early


def _peak_strain(
    e_det: FloatArray,
    preload: FloatArray,
    fiber_offset: FloatArray,
    fiber_radius: FloatArray,
    L: FloatArray,
    c: DesignConstraints,
) -> FloatArray:
    """(N,) peak fiber strain (|dy_fbg| + r_fbg) max|dtheta/ds| + P/EA after ``e_det`` plus the
    post-buckling travel; inf past the end of the first-mode branch."""
    g_end = (e_det + c.post_buckling_travel) / L
    peak = (np.abs(fiber_offset) + fiber_radius) * _peak_curvature(g_end) / L + preload
    return np.asarray(np.where(g_end > E_OVER_L_MAX, np.inf, peak))


def _checks(
    depth_ratio: FloatArray,
    contact_ratio: FloatArray,
    delta_stiff: FloatArray,
    detection: FloatArray,
    floor: FloatArray,
    bias: FloatArray,
    peak: FloatArray,
    c: DesignConstraints,
) -> dict[str, tuple[FloatArray, FloatArray, bool]]:
    """(value, limit, upper) per check, (N,) arrays, in ``CHECKS`` order (no ``thickness`` for
    a half-space)."""

    def limit(value: float) -> FloatArray:
        return np.full_like(depth_ratio, value)

    checks: dict[str, tuple[FloatArray, FloatArray, bool]] = {
        "depth": (depth_ratio, limit(c.max_depth_ratio), True)
    }
    if c.thickness is not None:
        checks["thickness"] = (contact_ratio, limit(c.max_layer_strain), True)
    checks["resolution"] = (delta_stiff, limit(c.resolution_multiple * c.encoder_resolution), False)
    checks["detection"] = (detection, floor, False)
    checks["delta_bias"] = (bias, c.max_bias_fraction * delta_stiff, True)
    checks["fiber_strain"] = (peak, limit(c.strain_limit), True)
    return checks


def checked_range(modulus_range: tuple[float, float]) -> tuple[float, float]:
    lo, hi = (float(v) for v in modulus_range)
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo <= hi):
        raise ValueError(f"modulus range must be 0 < E_min <= E_max (Pa), got {modulus_range!r}")
    return lo, hi


def evaluation(
    design: SensorDesign, a: Assessment, i: int, rng: tuple[float, float]
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
    rng = checked_range(modulus_range)
    if not design.exposed_length >= c.grating_reach:
        raise ValueError(
            f"exposed length {design.exposed_length * 1e3:.3g} mm leaves gratings inside the "
            f"tube: they reach {c.grating_reach * 1e3:.3g} mm from the tip"
        )
    section = design.section()

    def one(x: float) -> FloatArray:
        return np.array([x], dtype=np.float64)

    arrays = assess(
        one(section.EI),
        one(design.across_rigidity()),
        one(section.EA),
        one(section.fiber_offset),
        one(design.fiber_radius),
        one(design.tip_radius),
        one(design.exposed_length),
        rng,
        c,
        one(design.linear_mass()),
    )
    return evaluation(design, arrays, 0, rng)
