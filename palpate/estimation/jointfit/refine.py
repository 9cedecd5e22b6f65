"""Step 2 of the joint fit: refine (log E, x0, P0) with a robust loss and the effective variance.

``scipy.optimize.least_squares`` with ``soft_l1`` (``f_scale`` in noise units) on the residuals
standardised by the effective variance::

    r_i = (P_i - P0 - E f(delta_i)) / sigma_i,
    sigma_i^2 = sigma_P,i^2 (1 + c E f'(delta_i))^2 + (E f'(delta_i))^2 (sigma_e,i^2 + q^2/12),

the load's noise plus the depth's (the strain-inferred shortening and the encoder's
quantisation q), delta_i = depth_base_i - c P_i - x0 with the rig's compliance c (the measured
load's noise then enters the depth too, hence the factor on sigma_P). E enters as log E (it
stays positive and its steps are relative), P0 in units of the median sigma_P and x0 is scaled
by the scan's grid step, so that the three parameters are of comparable size to the solver.

Cost: one vectorised law evaluation (value and slope) per residual evaluation; the Jacobian is
``least_squares``'s finite differences; at most ``max_nfev`` evaluations.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..beam.elastica._scipy import least_squares
from ..belief import Hypothesis
from ..contact.law import ContactLaw
from .record import Record
from .result import FitFailed
from .scan import SCAN_POINTS, SCAN_STEP, Start

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class ResidualModel:
    """The standardised residuals and their sigmas as functions of theta = (log E, x0[, P0']).

    Attributes:
        law: the contact law.
        force, depth_base, sigma_force: the record's (N,) arrays (``record.Record``).
        var_depth: (N,) variance of the depth, sigma_e^2 + q^2/12 (m^2).
        compliance: c (m/N); ``depth_base`` already has c P taken out.
        p_scale: P0 = theta[2] p_scale (N).
        load_offset: whether theta carries P0 (else P0 = 0).
    """

    law: ContactLaw
    force: FloatArray
    depth_base: FloatArray
    sigma_force: FloatArray
    var_depth: FloatArray
    p_scale: float
    load_offset: bool
    compliance: float = 0.0

    def _variance(self, slope: FloatArray) -> FloatArray:
        load = self.sigma_force * (1.0 + self.compliance * slope)
        return np.asarray(load * load + slope * slope * self.var_depth)

    def sigma(self, theta: FloatArray) -> FloatArray:
        """(N,) effective standard deviations sigma_i (N) at theta."""
        f, df = self.law.shape(self.depth_base - theta[1])
        del f
        return np.asarray(np.sqrt(self._variance(math.exp(theta[0]) * df)))

    def residuals(self, theta: FloatArray) -> FloatArray:
        """(N,) standardised residuals r_i at theta (the refinement's objective)."""
        f, df = self.law.shape(self.depth_base - theta[1])
        E = math.exp(theta[0])
        P0 = theta[2] * self.p_scale if self.load_offset else 0.0
        return np.asarray((self.force - P0 - E * f) / np.sqrt(self._variance(E * df)))


@dataclass(frozen=True, eq=False)
class Refined:
    """The refined fit.

    Attributes:
        hypothesis: the law and compliance it was fitted with.
        model: the residual model it minimised.
        theta: the solution in the model's parameters.
        jac: (N, len(theta)) Jacobian of the standardised residuals there.
        modulus, contact, load_offset: E (Pa), x0 (m), P0 (N; 0 when not fitted).
        depth: (N,) indentation delta = depth_base - x0 (m).
        n_contact: samples with delta > 0.
        nfev: residual evaluations.
    """

    hypothesis: Hypothesis
    model: ResidualModel
    theta: FloatArray
    jac: FloatArray
    modulus: float
    contact: float
    load_offset: float
    depth: FloatArray
    n_contact: int
    nfev: int


def refine(
    hypothesis: Hypothesis,
    record: Record,
    start: Start,
    encoder_resolution: float,
    *,
    f_scale: float,
    max_nfev: int,
) -> Refined:
    """Robust least squares of ``hypothesis`` from ``start`` (the scan's, or a profile's best
    point), x0 bounded to the search window; ``encoder_resolution`` (m) adds its quantisation
    to the depth's variance.

    Raises:
        FitFailed: least squares raised or did not converge.
    """
    var_depth = record.sigma_shortening**2 + encoder_resolution**2 / 12.0
    depth_base = record.depth_base_at(hypothesis.compliance)
    model = ResidualModel(
        hypothesis.law,
        record.force,
        depth_base,
        record.sigma_force,
        var_depth,
        start.p_scale,
        start.load_offset,
        hypothesis.compliance,
    )
    sol = _solve(model, start, f_scale, max_nfev)
    E_hat, x0_hat = math.exp(float(sol.x[0])), float(sol.x[1])
    P0_hat = float(sol.x[2]) * start.p_scale if start.load_offset else 0.0
    depth = depth_base - x0_hat
    n_contact = int(np.count_nonzero(depth > 0))
    return Refined(
        hypothesis, model, sol.x, sol.jac, E_hat, x0_hat, P0_hat, depth, n_contact, int(sol.nfev)
    )


def require_contact(fit: Refined, min_contact_points: int) -> None:
    """FitFailed unless at least ``min_contact_points`` samples lie past the fitted x0."""
    if fit.n_contact < min_contact_points:
        raise FitFailed(
            f"no contact: {fit.n_contact} samples past the fitted contact point, the fit needs "
            f"{min_contact_points}",
            fit.n_contact,
            fit.nfev,
        )


def _solve(model: ResidualModel, start: Start, f_scale: float, max_nfev: int) -> Any:
    """scipy's OptimizeResult of the refinement; FitFailed when it raised or did not converge."""
    lo, hi = start.lo, start.hi
    x0_scale = max(1e-6, min((hi - lo) / SCAN_POINTS, SCAN_STEP))
    n_par = start.theta.size
    try:
        sol = least_squares(
            model.residuals,
            start.theta,
            loss="soft_l1",
            f_scale=f_scale,
            bounds=([-np.inf, lo, -np.inf][:n_par], [np.inf, hi, np.inf][:n_par]),
            x_scale=np.array([1.0, x0_scale, 1.0][:n_par]),
            max_nfev=max_nfev,
        )
    except (ValueError, FloatingPointError) as exc:
        raise FitFailed(f"least squares failed: {exc}") from exc
    if sol.status <= 0 or not np.all(np.isfinite(sol.x)):
        raise FitFailed(f"least squares did not converge: {sol.message}", nfev=int(sol.nfev))
    return sol
