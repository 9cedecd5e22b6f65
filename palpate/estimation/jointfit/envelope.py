"""Step 4 of the joint fit: profile every hypothesis in every model form, and the envelope.

The thin-layer series was derived for a paraboloid; with Sneddon's sphere its layer ratio can
be sqrt(R delta)/h (published, used for the estimate) or a/h, and the data cannot tell them
apart. Each hypothesis of the belief (``estimation.belief``) is profiled in each form with the
same weights (``profile``); a form's interval is the profile over x0 and the belief's open
properties together (its family), and the interval reported is the envelope of the forms'
intervals and of the estimate, widened by the model-form bound (``modelform``): it holds the
modulus whichever form the sample follows. ``model_spread`` is the difference between the
forms' moduli (a bias of known sign for each form, not a random error to add in quadrature).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..belief import Hypothesis
from ..contact.law import ContactLaw, validity_warnings
from .modelform import model_form, widened
from .noise import Noise
from .profile import Candidate, Profile, family_profiles
from .record import Record
from .refine import Refined
from .result import FitFailed, JointFit
from .scan import Start

FloatArray = NDArray[np.float64]


def other_forms(law: ContactLaw) -> tuple[ContactLaw, ...]:
    """The equally defensible variants of ``law`` (the other thin-layer ratio of the Dimitriadis
    series with Sneddon's sphere; none when the choice does not arise, as with the exact law)."""
    if law.thickness is None or not law.large_indentation or law.layer_law == "exact":
        return ()
    if law.layer_ratio_from == "published":
        return (dataclasses.replace(law, layer_ratio_from="sphere"),)
    return (dataclasses.replace(law, layer_ratio_from="published"),)


@dataclass(frozen=True)
class Found:
    """The profiles of every family (model form 0 = the laws as given, 1 = the other layer
    ratio), and the hypothesis (index) of each family's best point."""

    families: list[Profile | None]
    best_hypothesis: list[int]


def profile_hypotheses(
    hypotheses: Sequence[Hypothesis],
    record: Record,
    start: Start,
    fit: Refined,
    noise: Noise,
    span: float,
    weights_at: Callable[[float], FloatArray],
) -> Found:
    """Every hypothesis in each of its forms, profiled over x0 from ``fit.contact +- span``
    (m) within the search window with the frozen noise model: its threshold, and per
    compliance c the weights ``weights_at(c)`` (the effective variance depends on c).

    Raises:
        FitFailed: a form's profile found no contact position with a positive load.
    """
    compliances = sorted({h.compliance for h in hypotheses})
    bases = []
    for c in compliances:
        depth_base = record.depth_base_at(c)
        bases.append((depth_base, weights_at(c)))
    candidates: list[Candidate] = []
    owner: list[int] = []
    for j, hyp in enumerate(hypotheses):
        base = compliances.index(hyp.compliance)
        for family, law in enumerate((hyp.law, *other_forms(hyp.law))):
            candidates.append(Candidate(law, base, family))
            owner.append(j)
    window = (start.lo, start.hi)
    families = family_profiles(
        candidates,
        bases,
        record.force,
        fit.contact,
        span,
        noise.threshold,
        window,
        start.load_offset,
        noise.scale2,
    )
    if any(prof is None for prof in families):
        raise FitFailed(
            "profile likelihood failed: no contact position gives a positive load",
            fit.n_contact,
            fit.nfev,
        )
    best = [owner[prof.best] for prof in families if prof is not None]
    return Found(families, best)


def envelope(
    fit: Refined,
    noise: Noise,
    found: Found,
    confidence: float,
    misalignment: float | None,
    record_start: float,
    profiled: tuple[str, ...],
    hypotheses: int,
) -> JointFit:
    """The successful :class:`JointFit` of the estimate ``fit`` (fitted with the best
    hypothesis) and the families' profiles; ``misalignment`` (rad) is for the validity flags,
    ``record_start`` (m) the record's first stage position.

    Raises:
        FitFailed: the modulus or interval is not finite.
    """
    law = fit.hypothesis.law
    max_depth = float(fit.depth.max())
    warnings = list(validity_warnings(law, max_depth, misalignment))
    ok_profiles = [prof for prof in found.families if prof is not None]
    E_hat = fit.modulus if hypotheses == 1 else ok_profiles[0].center
    ci_low = min(E_hat, *(prof.ci_low for prof in ok_profiles))
    ci_high = max(E_hat, *(prof.ci_high for prof in ok_profiles))
    eps = model_form(law, max_depth).total
    ci_low, ci_high = widened(E_hat, ci_low, ci_high, eps)
    spread = max(abs(prof.modulus - ok_profiles[0].modulus) for prof in ok_profiles)
    edge = any(prof.edge for prof in ok_profiles)
    warnings.extend(_fit_warnings(edge, fit.contact < record_start, noise.rho))
    if not np.all(np.isfinite([ci_low, ci_high, E_hat])) or ci_low <= 0.0:
        raise FitFailed(
            "non-finite modulus or interval (or an interval reaching 0)", fit.n_contact, fit.nfev
        )
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
        max_depth=max_depth,
        rms=float(np.sqrt(np.mean(r * r))),
        rho=noise.rho,
        noise_scale=math.sqrt(noise.scale2),
        model_spread=spread,
        model_form=eps,
        profiled=profiled,
        hypotheses=hypotheses,
        best=fit.hypothesis.describe(),
        nfev=fit.nfev,
        law=law.name,
        warnings=tuple(warnings),
    )


EDGE_WARNING = "the contact position's interval reaches the record's edge"
BEFORE_WARNING = "contact before the record's first sample: the baseline before contact is unseen"
CORRELATED_WARNING = "residuals are correlated"


def _fit_warnings(edge: bool, before: bool, rho: float) -> list[str]:
    """The fit's own diagnostics: an interval cut by the record's edge, a contact before the
    record, correlated residuals."""
    out = []
    if edge:
        out.append(EDGE_WARNING)
    if before:
        out.append(BEFORE_WARNING)
    if rho > 0.5:
        out.append(
            f"{CORRELATED_WARNING} (lag-1 {rho:.2f}): the model misses part of the curve; "
            f"the interval is widened by {math.sqrt((1 + rho) / (1 - rho)):.2g}x"
        )
    return out
