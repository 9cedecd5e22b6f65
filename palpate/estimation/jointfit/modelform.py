"""Step 5 of the joint fit: the model-form uncertainty, a documented bound on what the
estimator's closed forms leave out, added to E's interval.

The force law (Sneddon's sphere times the Dimitriadis bracket, ``estimation.contact.law``) is
exact for none of the tissues the sensor meets. What the literature says about its accuracy:

- thin layer (Dimitriadis et al. 2002, Biophys. J. 82:2798, and the exact linear-elastic layer
  solutions it was checked against): the series is exact to first order in
  chi = sqrt(R delta)/h; truncated, it departs from the exact layer by about 1 % at chi = 0.2 and
  by several % at chi = 0.5 (bonded, nu -> 0.5; see docs/tissue-fe.md): a relative error of about
  ``LAYER_SERIES * chi^2`` (0.25: 1 % at 0.2, 6 % at 0.5);
- depth (Hertz's range): Hertz holds for delta/R <= 0.1 (``estimation.contact.hertz``); Sneddon's
  sphere removes the geometric part of the error beyond (-0.1 delta/R to first order), but it is
  still linear elasticity, and soft tissue and gels stiffen at finite strain (neo-Hookean and
  second-order elastic solutions depart from the linear ones at first order in delta/R: Lin et
  al. 2009, Biomech. Model. Mechanobiol. 8:345; Du et al. 2022, arXiv:2209.05646): a relative
  error of about ``FINITE_STRAIN * delta/R`` (0.1: 1 % at Hertz's limit, 3 % at delta/R = 0.3).

- a neo-Hookean law (``ContactLaw.material``) carries the finite-strain departure D to second
  order (``estimation.contact.finite_strain``): the correction moves the estimate, not the bound.
  The
  material is the operator's belief, and tissue's second-order behaviour (Mooney-Rivlin,
  Ogden, Fung) departs from the neo-Hookean one at the same order as the correction itself, so
  the literature's ``FINITE_STRAIN * strain`` stays; it is raised where the correction's own
  residual could be larger: the next order, ``max |D| s`` with ``s = delta/R + delta/h`` (the
  second order is within 0.2 % of the world's finite elements to delta/h = 0.2 with a
  frictionless tip, 0.44 % at 0.3: docs/layer-law.md), plus ``FINITE_STRAIN (delta/R - 0.3)``
  past delta/R = 0.3, where it is checked (1-3 % off at 0.6); a sticking tip's departure
  bridges two limits (``estimation.contact.finite_strain.departure``): on a bonded layer half
  their spread in quadrature; on a sliding one, whose FE leaves the limits, the stick's whole
  departure from the frictionless law (``_stick``).

The two are independent and combine in quadrature, at the deepest indentation of the record
(where the load, hence the leverage on E, is largest): ``eps``. It is a bound on a bias of
unknown sign, not noise, so it is not tuned to any world: E's interval half-widths are combined
with ``eps E`` in quadrature (as a GUM type-B component), around the estimate. The spread
between the two equally defensible layer ratios (``envelope``) is kept apart, as the envelope
of their intervals. ``JointFit.model_form`` reports eps.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..contact.finite_strain.table import departure_curve, stick_spread_curve
from ..contact.law import ContactLaw

LAYER_SERIES = 0.25
FINITE_STRAIN = 0.1
SECOND_ORDER_DEPTH = 0.3
"""delta/R to which the neo-Hookean law's second order is checked against the world's FE."""


@dataclass(frozen=True)
class ModelForm:
    """The relative model-form uncertainty of the force law at one depth, by source."""

    layer_series: float
    finite_strain: float

    @property
    def total(self) -> float:
        """eps, the sources in quadrature."""
        return math.hypot(self.layer_series, self.finite_strain)


def model_form(law: ContactLaw, max_depth: float) -> ModelForm:
    """The model-form uncertainty of ``law`` at depth ``max_depth`` (m, >= 0)."""
    if not (math.isfinite(max_depth) and max_depth >= 0.0):
        raise ValueError(f"max_depth must be finite and >= 0 m, got {max_depth!r}")
    strain = max_depth / law.tip_radius
    if law.layer_law == "exact" and law.thickness is not None:
        strain = max(strain, max_depth / law.thickness)
    series = 0.0 if law.layer_law == "exact" else _series(law, max_depth)
    if law.material != "linear":
        return ModelForm(series, max(FINITE_STRAIN * strain, _finite_strain(law, max_depth)))
    return ModelForm(series, FINITE_STRAIN * strain)


def _series(law: ContactLaw, max_depth: float) -> float:
    chi = float(law.layer_ratio(max_depth))
    return LAYER_SERIES * chi * chi


def _finite_strain(law: ContactLaw, max_depth: float) -> float:
    """What a neo-Hookean law's second-order departure leaves at ``max_depth`` (m)."""
    curve = law.finite_strain
    assert curve is not None
    ratio = max_depth / law.tip_radius
    strain = ratio * curve.scale
    depths = np.linspace(0.0, ratio, 33)
    out = float(np.max(np.abs(curve.at(depths)[0]))) * strain
    out += FINITE_STRAIN * max(0.0, ratio - SECOND_ORDER_DEPTH)
    if law.tip == "sticking":
        out = math.hypot(out, _stick(law, depths))
    return out


def _stick(law: ContactLaw, depths: np.ndarray) -> float:
    """What the sticking tip's approximation may miss over ``depths`` (delta/R): on a bonded
    layer half the spread of its two limits, which hold the world's FE in every table checked;
    on a sliding one the stick's whole effect (its departure against the frictionless one),
    since there the FE leaves the limits (under the lung's 10 mm tip, h/R 0.16-0.25, by up to
    2-6 % of the force at delta/h 0.2-0.25: docs/layer-law.md)."""
    if law.bonded:
        spread = stick_spread_curve(law.poisson, law.bonded, law.inverse_thickness)
        return float(np.max(spread.at(depths)[0]))
    stick = departure_curve(law.poisson, law.bonded, law.inverse_thickness, "sticking")
    free = departure_curve(law.poisson, law.bonded, law.inverse_thickness, "frictionless")
    return float(np.max(np.abs(stick.at(depths)[0] - free.at(depths)[0])))


def widened(modulus: float, ci_low: float, ci_high: float, eps: float) -> tuple[float, float]:
    """E's interval with the model-form bound ``eps`` (relative) combined in quadrature with
    each half-width around ``modulus`` (all Pa)."""
    down = math.hypot(modulus - ci_low, eps * modulus)
    up = math.hypot(ci_high - modulus, eps * modulus)
    return modulus - down, modulus + up
