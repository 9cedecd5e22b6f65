"""Step 4 of the joint fit: the envelope of the model forms' intervals, and the result.

The thin-layer series was derived for a paraboloid; with Sneddon's sphere its layer ratio can
be sqrt(R delta)/h (published, used for the estimate) or a/h, and the data cannot tell them
apart. Each form (:func:`other_forms`) is profiled with the same weights (``profile``), and the
interval reported is the envelope of the forms' intervals and of the estimate: it holds the
modulus whichever form the sample follows. ``model_spread`` is the difference between the forms'
moduli (a bias of known sign for each form, not a random error to add in quadrature).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from estimation.corrections import ContactLaw, validity_warnings
from estimation.jointfit.noise import Noise
from estimation.jointfit.profile import Profile, profiles
from estimation.jointfit.record import Record
from estimation.jointfit.refine import Refined
from estimation.jointfit.result import FitFailed, JointFit
from estimation.jointfit.scan import Start


def other_forms(law: ContactLaw) -> tuple[ContactLaw, ...]:
    """The equally defensible variants of ``law`` (the other thin-layer ratio with Sneddon's
    sphere; none when the choice does not arise)."""
    if law.thickness is None or not law.large_indentation:
        return ()
    if law.layer_ratio_from == "published":
        return (dataclasses.replace(law, layer_ratio_from="sphere"),)
    return (dataclasses.replace(law, layer_ratio_from="published"),)


def profile_forms(
    law: ContactLaw, record: Record, start: Start, fit: Refined, noise: Noise, span: float
) -> list[Profile | None]:
    """The profiles of ``law`` and of its other forms, in that order, over x0 from
    ``fit.contact +- span`` (m) within the search window, with the frozen noise model."""
    forms = (law, *other_forms(law))
    return profiles(
        forms,
        record.depth_base,
        record.force,
        noise.weights,
        fit.contact,
        span,
        noise.threshold,
        start.lo,
        start.hi,
        start.load_offset,
    )


def envelope(
    law: ContactLaw,
    fit: Refined,
    noise: Noise,
    found: Sequence[Profile | None],
    confidence: float,
    misalignment: float | None,
) -> JointFit:
    """The successful :class:`JointFit`: ``found`` holds the profiles of ``law`` and then of its
    other forms, in :func:`other_forms` order; ``misalignment`` (rad) is for the validity flags.

    Raises:
        FitFailed: a form's profile found no contact position with a positive load, or the
            modulus or interval is not finite.
    """
    warnings = list(validity_warnings(law, float(fit.depth.max()), misalignment))
    if any(prof is None for prof in found):
        raise FitFailed(
            "profile likelihood failed: no contact position gives a positive load",
            fit.n_contact,
            fit.nfev,
        )
    ok_profiles = [prof for prof in found if prof is not None]
    E_hat = fit.modulus
    ci_low = min(E_hat, *(prof.ci_low for prof in ok_profiles))
    ci_high = max(E_hat, *(prof.ci_high for prof in ok_profiles))
    spread = max(abs(prof.modulus - ok_profiles[0].modulus) for prof in ok_profiles)
    warnings.extend(_fit_warnings(any(prof.edge for prof in ok_profiles), noise.rho))
    if not np.all(np.isfinite([ci_low, ci_high, E_hat])):
        raise FitFailed("non-finite modulus or interval", fit.n_contact, fit.nfev)
    r = noise.residuals
    return JointFit(
        success=True,
        message="ok",
        modulus=E_hat,
        contact=fit.contact,
        load_offset=fit.load_offset,
        ci_low=ci_low,
        ci_high=ci_high,
        contact_low=min(prof.contact_low for prof in ok_profiles),
        contact_high=max(prof.contact_high for prof in ok_profiles),
        confidence=confidence,
        n_points=r.size,
        n_contact=fit.n_contact,
        max_depth=float(fit.depth.max()),
        rms=float(np.sqrt(np.mean(r * r))),
        noise_scale=math.sqrt(noise.scale2),
        model_spread=spread,
        nfev=fit.nfev,
        law=law.name,
        warnings=tuple(warnings),
    )


def _fit_warnings(edge: bool, rho: float) -> list[str]:
    """The fit's own diagnostics: an interval cut by the search window, correlated residuals."""
    out = []
    if edge:
        out.append("the contact position's interval reaches the search window's edge")
    if rho > 0.5:
        out.append(
            f"residuals are correlated (lag-1 {rho:.2f}): the model misses part of the curve; "
            f"the interval is widened by {math.sqrt((1 + rho) / (1 - rho)):.2g}x"
        )
    return out
