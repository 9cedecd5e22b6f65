"""The joint fit's recipe: check the record, scan, refine, profile, envelope."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..belief import Belief, Hypothesis
from ..contact.law import ContactLaw
from .beliefcheck import contradictions, law_curves
from .envelope import Found, envelope, profile_hypotheses
from .noise import (
    Noise,
    frozen_noise,
    profile_span,
    require_significance,
)
from .pooling import Terms
from .record import Record, check_options, checked_record
from .refine import Refined, refine, require_contact
from .result import FitFailed, JointFit
from .scan import Start, scan

FloatArray = NDArray[np.float64]

MIN_POINTS = 20
MIN_CONTACT_POINTS = 10


def joint_fit(
    advance: ArrayLike,
    force: ArrayLike,
    shortening: ArrayLike,
    law: ContactLaw | Belief,
    *,
    sigma_force: ArrayLike,
    sigma_shortening: ArrayLike = 0.0,
    encoder_resolution: float = 0.0,
    contact_guess: float | None = None,
    search: float = 1.0e-3,
    confidence: float = 0.95,
    f_scale: float = 3.0,
    load_offset: bool = True,
    misalignment: float | None = None,
    min_points: int = MIN_POINTS,
    min_contact_points: int = MIN_CONTACT_POINTS,
    max_nfev: int = 200,
) -> JointFit:
    """Fit E and the contact position x0 on a loading record (method: ``estimation.jointfit``).

    Args:
        advance, force, shortening: (N,) stage positions u (m) from before contact to the end
            of loading, and the axial loads P (N) and beam end shortenings e (m) from the strains.
        law: the contact law ``F = E f(delta)``, or a :class:`~estimation.belief.Belief` (what
            is known of the sample and the rig's compliance, with ranges profiled over).
        sigma_force, sigma_shortening: (N,) or scalar standard deviations of P (N, > 0), e (m).
        encoder_resolution: one encoder count q of stage advance (m): q^2/12 of depth variance.
        contact_guess: a first guess of x0 (m), e.g. ``estimation.detect.contact``'s: one more
            point of the scan, which covers the whole record regardless.
        search: how far before the record's first stage position x0 may lie (m, >= 0).
        confidence: the interval's level, in (0, 1); f_scale: the robust loss's soft threshold,
            in noise units.
        load_offset: fit a constant load offset P0 (the sensor's zero error) beside E and x0;
            False: the load is taken as exactly 0 before contact.
        misalignment: angle (rad) between the sensor axis and the surface normal, for the flags.
        min_points, min_contact_points: below these the fit is refused (success False).
        max_nfev: least-squares budget.

    Raises:
        ValueError: non-finite or mismatched arrays, non-positive sigmas, bad options.
    """
    belief = law if isinstance(law, Belief) else Belief.from_law(law)
    record = checked_record(advance, force, shortening, sigma_force, sigma_shortening)
    check_options(confidence, search, f_scale, encoder_resolution)
    provisional = belief.provisional()
    try:
        # 1. scan x0 (E, P0 in closed form); 2. refine robustly; 3. the noise model
        located = (contact_guess, search, load_offset, min_points, min_contact_points)
        start, fit = _located(provisional, record, located, encoder_resolution, f_scale, max_nfev)
        noise = frozen_noise(fit, f_scale, confidence)
        require_significance(fit, noise)
        # 4. profile every hypothesis of the belief in every form; the estimate at the best one
        refit = _Refit(record, start, fit, encoder_resolution, f_scale, max_nfev)
        return _profiled(belief, refit, noise, confidence, misalignment, min_contact_points)
    except FitFailed as failure:
        return failure.result(record.n, confidence, provisional.law.name)


def _located(
    provisional: Hypothesis,
    record: Record,
    located: tuple[float | None, float, bool, int, int],
    encoder_resolution: float,
    f_scale: float,
    max_nfev: int,
) -> tuple[Start, Refined]:
    """Steps 1-2 of :func:`joint_fit` under the provisional hypothesis: the contact scanned over
    the record, then refined robustly; ``located`` is (contact_guess, search, load_offset,
    min_points, min_contact_points). Raises FitFailed where the record cannot carry a fit."""
    contact_guess, search, load_offset, min_points, min_contact_points = located
    if record.n < min_points:
        raise FitFailed(f"too few points: {record.n} samples, the fit needs {min_points}")
    start = scan(provisional, record, contact_guess, search, load_offset)
    fit = refine(provisional, record, start, encoder_resolution, f_scale=f_scale, max_nfev=max_nfev)
    require_contact(fit, min_contact_points)
    return start, fit


def _profiled(
    belief: Belief,
    refit: _Refit,
    noise: Noise,
    confidence: float,
    misalignment: float | None,
    min_contact_points: int,
) -> JointFit:
    """Step 4 and the result: every hypothesis of ``belief`` profiled (each compliance with
    its own weights), the estimate refined at the best one, the envelope."""
    fit, record = refit.fit, refit.record
    span = profile_span(fit, noise.scale2, refit.start.hi - refit.start.lo)
    hypotheses = belief.hypotheses(float(fit.depth.max()), float(record.force.max()))

    def weights_at(compliance: float) -> FloatArray:
        return refit.weights_at(compliance, noise.weights, confidence)

    found = profile_hypotheses(hypotheses, record, refit.start, fit, noise, span, weights_at)
    best = hypotheses[found.best_hypothesis[0]]
    if best != fit.hypothesis:
        fit = refit.at_best(best, found)
        require_contact(fit, min_contact_points)
    result = envelope(
        fit,
        noise,
        found,
        confidence,
        misalignment,
        float(record.advance.min()),
        belief.open_keys,
        len(hypotheses),
    )
    # 5. can the record contradict what the belief states as a point? (and the trial's share
    # of its sample's pooled fit: the same curves)
    compliance = fit.hypothesis.compliance
    base = (record.depth_base_at(compliance), weights_at(compliance))
    start = refit.start
    window = (max(start.lo, fit.contact - 3.0 * span), min(start.hi, fit.contact + 3.0 * span))
    curves = law_curves(
        belief, fit.hypothesis.law, base, record.force, window, start.load_offset, noise.scale2
    )
    found_against = contradictions(curves)
    terms = None
    if result.modulus is not None and result.modulus > 0.0:
        trimmed = {k: c.trimmed() for k, c in curves.items()}
        terms = Terms(result.modulus, result.model_form or 0.0, trimmed)
    return dataclasses.replace(result, warnings=result.warnings + found_against, terms=terms)


@dataclass(frozen=True)
class _Refit:
    """Refinements beside the provisional fit ``fit``: at another compliance (for its weights)
    and at the best hypothesis (the estimate)."""

    record: Record
    start: Start
    fit: Refined
    encoder_resolution: float
    f_scale: float
    max_nfev: int

    def _refine(self, hypothesis: Hypothesis, theta: FloatArray) -> Refined:
        s = self.start
        begin = Start(s.lo, s.hi, hypothesis.compliance, theta, s.p_scale, s.load_offset)
        return refine(
            hypothesis,
            self.record,
            begin,
            self.encoder_resolution,
            f_scale=self.f_scale,
            max_nfev=self.max_nfev,
        )

    def weights_at(self, compliance: float, own: FloatArray, confidence: float) -> FloatArray:
        """The frozen weights at ``compliance`` (m/N): the noise model of the provisional law
        refined there (``own``, the provisional's, at its compliance or if that fails). The
        effective variance depends on c through the fitted slope, so each compliance is
        profiled with the weights its own refinement would use."""
        if compliance == self.fit.hypothesis.compliance:
            return own
        hypothesis = dataclasses.replace(self.fit.hypothesis, compliance=compliance)
        try:
            refined = self._refine(hypothesis, self.fit.theta)
        except FitFailed:
            return own
        return frozen_noise(refined, self.f_scale, confidence).weights

    def at_best(self, best: Hypothesis, found: Found) -> Refined:
        """The estimate at the best hypothesis: refined from its profile's best point (the
        provisional fit when that does not converge or has no positive modulus)."""
        prof = found.families[0]
        if prof is None or prof.modulus <= 0.0:
            return self.fit
        theta = np.array(
            [math.log(prof.modulus), prof.best_contact, prof.best_offset / self.start.p_scale]
        )
        try:
            return self._refine(best, theta[: self.start.theta.size])
        except FitFailed:
            return self.fit
