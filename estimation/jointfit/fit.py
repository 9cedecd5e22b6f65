"""The joint fit's recipe: check the record, scan, refine, profile, envelope."""

from __future__ import annotations

from numpy.typing import ArrayLike

from estimation.corrections import ContactLaw
from estimation.jointfit.envelope import envelope, profile_forms
from estimation.jointfit.noise import frozen_noise, profile_span, require_significance
from estimation.jointfit.record import check_options, checked_record
from estimation.jointfit.refine import refine, require_contact
from estimation.jointfit.result import FitFailed, JointFit
from estimation.jointfit.scan import scan

MIN_POINTS = 20
MIN_CONTACT_POINTS = 10


def joint_fit(
    advance: ArrayLike,
    force: ArrayLike,
    shortening: ArrayLike,
    law: ContactLaw,
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
        law: the contact law ``F = E f(delta)``.
        sigma_force, sigma_shortening: (N,) or scalar standard deviations of P (N, > 0), e (m).
        encoder_resolution: one encoder count q of stage advance (m): q^2/12 of depth variance.
        contact_guess: first guess of x0 (m), e.g. ``estimation.detect_contact``'s; None: the
            middle of the advance. x0 is searched within contact_guess +- ``search`` (m).
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
    record = checked_record(advance, force, shortening, sigma_force, sigma_shortening)
    check_options(confidence, search, f_scale, encoder_resolution)
    try:
        if record.n < min_points:
            raise FitFailed(f"too few points: {record.n} samples, the fit needs {min_points}")
        # 1. scan x0 (E, P0 in closed form); 2. refine robustly; 3. profile x0; 4. the forms
        start = scan(law, record, contact_guess, search, load_offset)
        fit = refine(law, record, start, encoder_resolution, f_scale=f_scale, max_nfev=max_nfev)
        require_contact(fit, min_contact_points)
        noise = frozen_noise(fit, f_scale, confidence)
        require_significance(fit, noise)
        span = profile_span(fit, noise.scale2, search)
        found = profile_forms(law, record, start, fit, noise, span)
        return envelope(law, fit, noise, found, confidence, misalignment)
    except FitFailed as failure:
        return failure.result(record.n, confidence, law.name)
