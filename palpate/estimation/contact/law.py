"""Corrections to Hertz (paper Eq. 13) for thin layers and deep indentation, and validity flags.

Both corrections are published closed forms; the simulator's tissue (``sim.tissue``) uses the
same constants and kernels from here, but composes them differently (see below), so the
estimator's model is close to, not identical with, the world it measures.

- Large indentation, Sneddon's exact rigid *sphere* on a linear-elastic half-space (Sneddon 1965,
  Int. J. Eng. Sci. 3:47-57). With the contact radius ``a`` and ``y = artanh(a/R)``::

      delta = R y tanh(y),      F = E* R^2 [(1 + tanh(y)^2) y - tanh(y)],   E* = E / (1 - nu^2)

  It tends to Hertz, ``F = 4/3 E* sqrt(R) delta^1.5``, for ``delta << R`` (relative difference
  about ``-0.1 delta/R``).
- Finite thickness, Dimitriadis et al. 2002 (Biophys. J. 82:2798-2810, Eq. 12), a layer of
  thickness ``h`` on a rigid substrate, bonded or sliding: ``F = F_0 B(chi)``, the bracket and
  its coefficients in ``estimation.contact.layer`` (the sliding layer's from the frictionless base's
  kernel, not Dimitriadis' nu-dependent fit).

The estimator's law (:class:`ContactLaw`) is the published form: ``F_0`` Hertz or Sneddon,
times the bracket at ``chi = sqrt(R delta)/h`` with no continuation past ``chi = 1`` (a warning
instead). The simulator uses ``chi = a/h`` with the active law's contact radius and continues the
series linearly past ``chi = 1``. Every law here is linear in E: ``F = E f(delta)``, which the
joint fit (``estimation.jointfit``) uses to profile E out in closed form.

Pure vectorised functions; SI units (m, N, Pa); bad input raises ValueError naming it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .finite_strain.table import DepartureCurve, Tip, departure_curve
from .hertz import MAX_DEPTH_RATIO as MAX_DEPTH_RATIO_HERTZ
from .hertz import hertz_validity
from .layer import dimitriadis_bracket, layer_coefficients
from .layer_table import DEPTH_RATIO_MAX, LayerFactor, layer_factor
from .sneddon import sneddon_bracket, sneddon_y

FloatArray = NDArray[np.float64]

CHI_MAX = 1.0
"""Layer ratio up to which the Dimitriadis series is trusted (its small-chi expansion)."""

LayerLaw = Literal["exact", "dimitriadis"]
Material = Literal["linear", "neo-hookean"]

MAX_MISALIGNMENT = math.radians(5.0)
"""Angle between the sensor axis and the surface normal above which a warning is given: the
axial load then has a shear part and Eq. 13's normal indentation no longer holds (cos 5 deg =
0.996 on the normal component, but friction and tip sliding grow with the angle)."""


class _HalfSpace(NamedTuple):
    """The sphere's half-space law at depths delta >= 0: what every layer form shares."""

    root: FloatArray  # sqrt(R delta): Hertz's contact radius, the published layer ratio's
    a: FloatArray  # the contact radius: Sneddon's R tanh y, or root for Hertz
    f0: FloatArray  # F / E* on a half-space (m^2)
    y: FloatArray | None  # Sneddon's y (None for Hertz)
    t: FloatArray | None  # tanh y


def _half_space(R: float, dp: FloatArray, large_indentation: bool) -> _HalfSpace:
    """:class:`_HalfSpace` at depths ``dp`` >= 0 for tip radius R (Sneddon's sphere, or Hertz)."""
    root = np.sqrt(R * dp)
    if not large_indentation:
        return _HalfSpace(root, root, 4.0 / 3.0 * root * root * root / R, None, None)
    y = sneddon_y(dp / R)
    t = np.tanh(y)
    return _HalfSpace(root, R * t, R * R * sneddon_bracket(y, t), y, t)


# --------------------------------------------------------------------------- the estimator's law
@dataclass(frozen=True)
class ContactLaw:
    """Force per unit modulus of the spherical tip on the sample: ``F = E * shape(delta)``.

    Attributes:
        tip_radius: R (m).
        poisson: the sample's Poisson ratio (known, as in the paper).
        thickness: layer thickness h (m) on a rigid substrate; None for a half-space.
        bonded: the layer is glued to its substrate (Dimitriadis bonded) or slides on a
            frictionless base (:func:`layer_coefficients`).
        large_indentation: Sneddon's sphere instead of the Hertz paraboloid.
        layer_ratio_from: ``"published"``: chi = sqrt(R delta)/h as Dimitriadis published it;
            ``"sphere"``: chi = a/h with Sneddon's contact radius a = R tanh(y). The series was
            derived for the paraboloid, so with the sphere both are defensible; the joint fit
            uses the published one and the spread between the two as a model-form uncertainty.
            Only for ``layer_law="dimitriadis"``: the exact law has no such choice.
        layer_law: ``"exact"``: the layer's exact linear-elastic law for the sphere (or the
            paraboloid) at depth (``estimation.contact.layer_table``), trusted to chi = 3 and
            delta/R = 1; ``"dimitriadis"``: the published series, kept as a reference.
        material: ``"linear"`` elasticity, or a ``"neo-hookean"`` solid: the linear law times
            ``1 + D``, its second-order departure (``estimation.contact.finite_strain``).
        tip: the tip's contact, ``"frictionless"`` or ``"sticking"`` (full stick): it moves a
            neo-Hookean solid's departure (the linear law does not tell them apart: <= 0.3 %).
    """

    tip_radius: float
    poisson: float
    thickness: float | None = None
    bonded: bool = True
    large_indentation: bool = True
    layer_ratio_from: Literal["published", "sphere"] = "published"
    layer_law: LayerLaw = "exact"
    material: Material = "linear"
    tip: Tip = "frictionless"

    def __post_init__(self) -> None:
        if not (math.isfinite(self.tip_radius) and self.tip_radius > 0):
            raise ValueError(f"tip_radius must be a finite length > 0 m, got {self.tip_radius!r}")
        if self.thickness is not None and not (
            math.isfinite(self.thickness) and self.thickness > 0
        ):
            raise ValueError(f"thickness must be > 0 m or None, got {self.thickness!r}")
        layer_coefficients(self.poisson, self.bonded)  # validates poisson
        if self.layer_ratio_from not in ("published", "sphere"):
            raise ValueError(
                f"layer_ratio_from must be 'published' or 'sphere', got {self.layer_ratio_from!r}"
            )
        if self.layer_law not in ("exact", "dimitriadis"):
            raise ValueError(f"layer_law must be 'exact' or 'dimitriadis', got {self.layer_law!r}")
        if self.material not in ("linear", "neo-hookean"):
            raise ValueError(f"material must be 'linear' or 'neo-hookean', got {self.material!r}")
        if self.tip not in ("frictionless", "sticking"):
            raise ValueError(f"tip must be 'frictionless' or 'sticking', got {self.tip!r}")

    @property
    def name(self) -> str:
        base = "Sneddon sphere" if self.large_indentation else "Hertz"
        if self.thickness is None:
            return base
        kind = "bonded" if self.bonded else "non-bonded"
        if self.layer_law == "exact":
            return f"{base} on an exact {kind} layer (h = {self.thickness * 1e3:g} mm)"
        return f"{base} x Dimitriadis {kind} (h = {self.thickness * 1e3:g} mm)"

    @property
    def inverse_thickness(self) -> float:
        """R/h (0 for a half-space)."""
        return 0.0 if self.thickness is None else self.tip_radius / self.thickness

    @property
    def finite_strain(self) -> DepartureCurve | None:
        """The neo-Hookean departure's curve (None: a linear material)."""
        if self.material == "linear":
            return None
        return departure_curve(self.poisson, self.bonded, self.inverse_thickness, self.tip)

    @property
    def exact_layer(self) -> LayerFactor | None:
        """The exact law's layer factor against the half-space law (None: no layer, or the
        Dimitriadis series)."""
        if self.thickness is None or self.layer_law != "exact":
            return None
        ratio = self.thickness / self.tip_radius
        return layer_factor(self.poisson, self.bonded, ratio, self.large_indentation)

    def shape(self, delta: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """f(delta) = F/E (N/Pa) and df/ddelta, for depths ``delta`` (m); 0 where delta <= 0.

        Negative depths are allowed (no contact: F = 0), so a fit can place the contact point
        anywhere along the record.
        """
        d = np.asarray(delta, dtype=np.float64)
        if not np.all(np.isfinite(d)):
            raise ValueError("delta must be finite")
        R = self.tip_radius
        dp = np.maximum(d, 0.0)
        half = _half_space(R, dp, self.large_indentation)
        root, a, f0 = half.root, half.a, half.f0
        da = np.where(dp > 0, 0.5 * R / np.where(root > 0, root, 1.0), 0.0)  # d sqrt(R d)/dd
        sphere_ratio = self.layer_ratio_from == "sphere" and self.layer_law == "dimitriadis"
        if sphere_ratio and half.y is not None and half.t is not None:
            y, t = half.y, half.t
            sech2 = 1.0 - t * t
            da = sech2 / (t + y * sech2 + (y == 0))
            root = a
        df0 = 2.0 * a  # dF/ddelta = 2 E* a for any axisymmetric frictionless indenter
        scale = 1.0 / (1.0 - self.poisson**2)
        if self.thickness is None:
            return self._strained(dp, scale * f0, scale * df0)
        exact = self.exact_layer
        if exact is not None:
            g, dg = exact.at(root / self.thickness)
            dchi = da / self.thickness
            return self._strained(dp, scale * f0 * g, scale * (df0 * g + f0 * dg * dchi))
        chi = root / self.thickness
        b, db = dimitriadis_bracket(chi, layer_coefficients(self.poisson, self.bonded))
        dchi = da / self.thickness
        return self._strained(dp, scale * f0 * b, scale * (df0 * b + f0 * db * dchi))

    def _strained(
        self, dp: FloatArray, f: FloatArray, df: FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        """The linear law's (f, df) at depths ``dp`` >= 0, times the material's ``1 + D``."""
        curve = self.finite_strain
        if curve is None:
            return np.asarray(f), np.asarray(df)
        d, dd = curve.at(dp / self.tip_radius)
        return np.asarray(f * (1.0 + d)), np.asarray(df * (1.0 + d) + f * dd / self.tip_radius)

    def force(self, modulus: float, delta: ArrayLike) -> FloatArray:
        """F (N) at depths ``delta`` for modulus E (Pa)."""
        return np.asarray(modulus * self.shape(delta)[0])

    def modulus(self, force: ArrayLike, delta: ArrayLike) -> FloatArray:
        """E (Pa) from one or more (F, delta) points (delta > 0): the law's inverse for E."""
        d = np.asarray(delta, dtype=np.float64)
        if not np.all(np.isfinite(d) & (d > 0)):
            raise ValueError("delta must be finite and > 0 to invert for the modulus")
        return np.asarray(np.asarray(force, dtype=np.float64) / self.shape(d)[0])

    def layer_ratio(self, delta: ArrayLike) -> FloatArray:
        """chi = sqrt(R delta)/h (0 for a half-space)."""
        d = np.maximum(np.asarray(delta, dtype=np.float64), 0.0)
        if self.thickness is None:
            return np.zeros_like(d)
        return np.asarray(np.sqrt(self.tip_radius * d) / self.thickness)


def shape_values(laws: Sequence[ContactLaw], delta: FloatArray) -> list[FloatArray]:
    """f(delta) = F/E (N/Pa) of each law at the same depths ``delta`` (m, any shape; 0 where
    delta <= 0): the values of :meth:`ContactLaw.shape`, bit for bit, without the derivative.

    Why it exists: the joint fit's x0 grids evaluate the law at ~250k depths per trial, for the
    estimator's law and its other layer-ratio form on the same grid. The half-space part (the
    Sneddon solve, most of the cost) depends only on the tip, the Poisson ratio and the
    half-space law, so it is computed once for all ``laws``, which must share those (thickness,
    bonding and layer ratio may differ). No finiteness check: the caller's depths are built from
    validated records.

    Raises:
        ValueError: no laws, or laws that differ in tip_radius, poisson or large_indentation.
    """
    if not laws:
        raise ValueError("shape_values needs at least one law")
    first = laws[0]
    half_space = (first.tip_radius, first.poisson, first.large_indentation)
    if any((law.tip_radius, law.poisson, law.large_indentation) != half_space for law in laws):
        raise ValueError("shape_values: the laws must share tip_radius, poisson, large_indentation")
    dp = np.maximum(delta, 0.0)
    half = _half_space(first.tip_radius, dp, first.large_indentation)
    f0 = half.f0
    scale = 1.0 / (1.0 - first.poisson**2)
    out: list[FloatArray] = []
    for law in laws:
        if law.thickness is None:
            value = scale * f0
        elif (exact := law.exact_layer) is not None:
            value = scale * f0 * exact.at(half.root / law.thickness)[0]
        else:
            radius = half.a if law.layer_ratio_from == "sphere" else half.root
            k = layer_coefficients(law.poisson, law.bonded)
            value = scale * f0 * dimitriadis_bracket(radius / law.thickness, k)[0]
        curve = law.finite_strain
        if curve is not None:
            value = value * (1.0 + curve.at(dp / law.tip_radius)[0])
        out.append(np.asarray(value))
    return out


LAYER_STRAIN_MAX = 0.2
"""Trusted compression of a layer, delta/h: past it a thin layer's finite strain (not in any
linear law) moves the force by several % (docs/estimation.md)."""
LAYER_STRAIN_MAX_NEO_HOOKEAN = 0.3
"""The same for a neo-Hookean law, which carries the departure to second order: checked
against the world's finite elements to delta/h = 0.3 (docs/layer-law.md)."""
DEPTH_RATIO_MAX_NEO_HOOKEAN = 0.6
"""Trusted sphere depth delta/R of a neo-Hookean law: its rows' reach (past it the departure is
extrapolated). It is within 0.65 % of the world's finite elements to delta/R = 0.3 and 1-3 %
off at 0.6, which the model-form bound carries (``jointfit.modelform``; docs/layer-law.md)."""


def validity_warnings(
    law: ContactLaw, delta_max: float, misalignment: float | None = None
) -> tuple[str, ...]:
    """Warnings (one sentence each) on using ``law`` up to depth ``delta_max`` (m).

    - the law's trusted domain: for the exact layer law (:func:`exact_domain_warnings`), its
      tables' reach in chi and delta/R and the layer's compression; for the Dimitriadis series,
      Hertz's small-strain range and the half-space condition (``estimation.contact.hertz``), said
      as
      corrected when the law corrects them, and chi beyond the series' range (CHI_MAX);
    - ``misalignment`` (rad, e.g. the inverse kinematics' residual angle) above MAX_MISALIGNMENT.
    """
    if not (math.isfinite(delta_max) and delta_max >= 0):
        raise ValueError(f"delta_max must be finite and >= 0 m, got {delta_max!r}")
    if law.layer_law == "exact":
        out = exact_domain_warnings(law, delta_max)
    else:
        out = _series_warnings(law, delta_max)
    if misalignment is not None:
        if not math.isfinite(misalignment):
            raise ValueError(f"misalignment must be finite (rad), got {misalignment!r}")
        if abs(misalignment) > MAX_MISALIGNMENT:
            out.append(
                f"sensor {math.degrees(abs(misalignment)):.1f} deg off the surface normal "
                f"(> {math.degrees(MAX_MISALIGNMENT):g} deg): the indentation is not normal"
            )
    return tuple(out)


def exact_domain_warnings(law: ContactLaw, delta_max: float) -> list[str]:
    """Where ``law`` (the exact layer law) is used past its trusted domain at depth
    ``delta_max`` (m): the sphere's depth (DEPTH_RATIO_MAX), the layer ratio its tables reach
    (``estimation.contact.layer_table.CHI_MAX`` or less), the layer's compression
    (LAYER_STRAIN_MAX).
    Each is a reason for ``suspect``; the half-space depth is said as corrected (Sneddon's
    sphere is exact)."""
    out: list[str] = []
    depth_ratio = delta_max / law.tip_radius
    if law.material != "linear" and depth_ratio > DEPTH_RATIO_MAX_NEO_HOOKEAN:
        out.append(
            f"indentation beyond the neo-Hookean law's trusted depth: delta/R up to "
            f"{depth_ratio:.3g} > {DEPTH_RATIO_MAX_NEO_HOOKEAN:g} (its departure is "
            f"extrapolated)"
        )
    if depth_ratio > DEPTH_RATIO_MAX:
        out.append(
            f"indentation beyond the exact law's trusted depth: delta/R up to {depth_ratio:.3g} "
            f"> {DEPTH_RATIO_MAX:g} (the law is extrapolated)"
        )
    elif depth_ratio > MAX_DEPTH_RATIO_HERTZ:
        note = "the paraboloid departs from the sphere"
        if law.large_indentation:
            note = "corrected with Sneddon's sphere (linear elasticity still assumed)"
            if law.material != "linear":
                note = "corrected with Sneddon's sphere and the neo-Hookean departure"
        out.append(
            f"indentation beyond Hertz's small-strain range: delta/R up to {depth_ratio:.3g}; "
            f"{note}"
        )
    exact = law.exact_layer
    if exact is None or law.thickness is None:
        return out
    chi = float(law.layer_ratio(delta_max))
    if chi > exact.reach:
        out.append(
            f"layer ratio sqrt(R delta)/h = {chi:.3g} beyond the exact layer law's trusted "
            f"domain (chi <= {exact.reach:.3g}): the thickness correction is extrapolated"
        )
    strain = delta_max / law.thickness
    if law.material != "linear":
        if strain > LAYER_STRAIN_MAX_NEO_HOOKEAN:
            out.append(
                f"the layer is compressed by delta/h = {strain:.3g} > "
                f"{LAYER_STRAIN_MAX_NEO_HOOKEAN:g}: beyond the second-order neo-Hookean law"
            )
    elif strain > LAYER_STRAIN_MAX:
        out.append(
            f"the layer is compressed by delta/h = {strain:.3g} > {LAYER_STRAIN_MAX:g}: "
            f"finite strain, outside every linear law, moves the force by several %"
        )
    return out


def _series_warnings(law: ContactLaw, delta_max: float) -> list[str]:
    """The Dimitriadis series' flags: Hertz's limits said as corrected, chi past CHI_MAX."""
    out: list[str] = []
    hv = hertz_validity(delta_max, law.tip_radius, law.thickness)
    for warning in hv.warnings:
        w, note = warning, ""
        if "small-strain" in w and law.large_indentation:
            note = "; corrected with Sneddon's sphere (linear elasticity still assumed)"
        elif "too thin" in w and law.thickness is not None:
            w = w.replace(" (the modulus is overestimated)", "")
            note = "; Dimitriadis thin-layer correction applied"
        out.append(w + note)
    chi = float(law.layer_ratio(delta_max))
    if chi > CHI_MAX:
        out.append(
            f"layer ratio sqrt(R delta)/h = {chi:.3g} beyond the Dimitriadis series' range "
            f"(chi <= {CHI_MAX:g}): the thickness correction is extrapolated"
        )
    return out
