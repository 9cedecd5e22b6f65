"""Step 3a of the joint fit: the noise model the interval is drawn with, frozen at the solution.

The profile likelihood (``profile``) needs fixed weights and a threshold on the weighted RSS:

- weights: the robust loss's IRLS weight (soft_l1: 1/sqrt(1 + (r/f_scale)^2)) over the
  effective variance sigma_i^2, both at the solution, i.e. the last IRLS step;
- ``s^2``: the nominal noise inflated by the model residual (reduced chi^2 when above 1) and by
  the residuals' lag-1 autocorrelation rho past contact ((1 + rho)/(1 - rho), the
  effective-sample-size factor for an AR(1) misfit), so a curve the model does not follow gets a
  wider interval rather than a falsely tight one;
- threshold: the chi^2(1) quantile at the confidence level, times s^2.

Two more things are read off the solution here: whether the contact model beats "no load at
all" by MIN_SIGNIFICANCE sigmas (else the record shows no contact), and the half-width the
profile grid starts from (8 standard deviations of x0 from the Jacobian).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from statistics import NormalDist

import numpy as np
from numpy.typing import NDArray

from .refine import Refined
from .result import FitFailed

FloatArray = NDArray[np.float64]

MAX_RHO = 0.95
MIN_SIGNIFICANCE = 5.0  # sigmas by which the contact model must beat "no load at all"


@dataclass(frozen=True, eq=False)
class Noise:
    """The noise model at the solution.

    Attributes:
        residuals: (N,) standardised residuals r_i.
        weights: (N,) w_i = robust weight / sigma_i^2 (1/N^2), frozen for the profile.
        rho: lag-1 autocorrelation of the residuals past contact, in [0, MAX_RHO].
        scale2: s^2, the factor the nominal noise variance is inflated by.
        threshold: the profile's RSS threshold, q_chi2(confidence) s^2.
    """

    residuals: FloatArray
    weights: FloatArray
    rho: float
    scale2: float
    threshold: float


def frozen_noise(fit: Refined, f_scale: float, confidence: float) -> Noise:
    """Weights, s^2 and threshold at the refined solution (see the module docstring)."""
    r = fit.model.residuals(fit.theta)
    robust = 1.0 / np.sqrt(1.0 + (r / f_scale) ** 2)  # soft_l1's IRLS weight
    w = robust / fit.model.sigma(fit.theta) ** 2
    dof = max(1, r.size - fit.theta.size)
    chi2_red = float(np.sum(robust * r * r)) / dof
    rho = lag1(r[fit.depth > 0])
    scale2 = max(1.0, chi2_red) * (1.0 + rho) / (1.0 - rho)
    threshold = NormalDist().inv_cdf(0.5 + 0.5 * confidence) ** 2 * scale2  # chi2(1) quantile
    return Noise(r, w, rho, scale2, threshold)


def lag1(r: FloatArray) -> float:
    """Lag-1 autocorrelation of residuals in record order, clipped to [0, MAX_RHO]."""
    if r.size < 3:
        return 0.0
    c = r - r.mean()
    denom = float(c @ c)
    if denom == 0.0:
        return 0.0
    return min(max(float(c[1:] @ c[:-1]) / denom, 0.0), MAX_RHO)


def require_significance(fit: Refined, noise: Noise) -> None:
    """FitFailed unless the fitted load beats "no contact at all" (a constant load, P0 alone,
    or none without the offset) by MIN_SIGNIFICANCE sigmas in the frozen weights."""
    P, w = fit.model.force, noise.weights
    null = P - float(w @ P) / float(np.sum(w)) if fit.model.load_offset else P
    fitted = P - fit.load_offset - fit.modulus * fit.model.law.shape(fit.depth)[0]
    gain = float(np.sum(w * null * null) - np.sum(w * fitted * fitted))
    if gain < MIN_SIGNIFICANCE**2 * noise.scale2:
        raise FitFailed(
            f"no contact: the fitted load is not significant (chi^2 gain {gain / noise.scale2:.3g} "
            f"over zero load, needs {MIN_SIGNIFICANCE**2:g})",
            fit.n_contact,
            fit.nfev,
        )


def profile_span(fit: Refined, scale2: float, search: float) -> float:
    """Half-width (m) of the first profile grid: 8 sd of x0 from the Jacobian (inflated by s^2),
    at least 2 um, at most ``search`` (also when the normal matrix is singular)."""
    jac = fit.jac  # of the standardised residuals in (log E, x0[, P0'])
    try:
        cov = np.linalg.inv(jac.T @ jac) * scale2
        sd_x0 = math.sqrt(max(cov[1, 1], 0.0))
        if not math.isfinite(sd_x0):
            raise np.linalg.LinAlgError("singular")
    except np.linalg.LinAlgError:
        sd_x0 = search
    return min(max(8.0 * sd_x0, 2e-6), search)
