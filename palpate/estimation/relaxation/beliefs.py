"""The relaxation fit over what the belief leaves open: one fit a hypothesis, one answer.

The joint fit profiles E over the belief's hypotheses (thickness, base, Poisson ratio,
compliance: ``estimation.belief``); a relaxation fit at the joint fit's best hypothesis alone
inherits that hypothesis's error. On a relaxing record the elastic fit's best is the wrong
place to stand: its misfit is the relaxation's, and it leans to whichever end of an open range
bends its law toward a relaxing curve (a lung-like layer of nu 0.49 told [0.45, 0.49] was read at
0.45 in every trial, and its relaxed modulus 10 % high with an interval that missed the truth).

So :func:`fit_over_beliefs` fits the relaxation (``fit_relaxation``) under every hypothesis and
combines them as the joint fit does, with one difference: which hypotheses the record allows.
Their fits differ in weighted RSS by tens of noise variances where the law's own model-form bound
(the joint fit's ``model_form``, eps, relative) allows thousands: with a tip grating's noise a
1 % bias of the law is ``sum (eps P_i / sigma_i)^2`` (``allowance``) in the same units, so a
difference below it says which law misses the tissue's finite strain and relaxation least, not
which Poisson ratio the tissue has (on the lung-like layers the RSS preferred nu = 0.49 for
every sample, those of 0.45 too). The plausible hypotheses are those within the chi^2(1)
quantile plus that allowance of the lowest RSS (in its noise variances); each modulus's interval
is the envelope of theirs; the number the middle of their numbers (a single hypothesis: its
own). The relaxation time, ``relaxes`` and ``complete`` are the best hypothesis's.

Usage::

    fit = fit_over_beliefs(record, belief, contact, modulus, model_form=eps)
    fit.relaxed, (fit.relaxed_low, fit.relaxed_high), fit.plausible
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from ..belief import Belief, Hypothesis
from ..jointfit.beliefcheck import alternatives, contradiction
from ..jointfit.pooling import chi2_quantile
from .fit import fit_relaxation, floor_rss
from .result import RelaxationFit, RelaxationRecord

PER_AXIS = 4  # values of each open property fitted (``thinned``)
MARGIN = 25.0
"""delta chi^2 past which an alternative to a stated point belief contradicts it on a relaxing
record (the elastic check's is 9): set from the relaxing lung-like layers with true beliefs,
where the relaxation law's own misfit gives a halved thickness up to 19 (docs/viscoelastic.md)."""


def fit_over_beliefs(
    record: RelaxationRecord,
    belief: Belief,
    contact: tuple[float, float, float],
    modulus: float,
    *,
    model_form: float = 0.0,
    confidence: float = 0.95,
) -> RelaxationFit:
    """The relaxation fit of ``record`` (its ``depth_base`` without any compliance: each
    hypothesis's ``c P`` is taken off) under each of ``belief``'s hypotheses, combined, and the
    belief check on the relaxed curve (module docstring)."""
    depth = float(np.max(record.depth_base)) - contact[0]
    hypotheses = thinned(belief.hypotheses(depth, float(np.max(record.load))))
    fits = [
        fit_relaxation(
            _less_compliance(record, h.compliance),
            h.law,
            contact,
            modulus,
            model_form=model_form,
            confidence=confidence,
        )
        for h in hypotheses
    ]
    done = [i for i, f in enumerate(fits) if f.success and f.rss is not None]
    if not done:
        return fits[0]
    at = min(done, key=lambda i: fits[i].rss or 0.0)
    best, scale = fits[at], fits[at].noise_scale or 1.0
    checked = _contradictions(record, belief, hypotheses[at], (contact, modulus), best)
    reach = chi2_quantile(confidence) + allowance(record, model_form) / scale
    floor = best.rss or 0.0
    plausible = [fits[i] for i in done if ((fits[i].rss or 0.0) - floor) / scale <= reach]
    return dataclasses.replace(
        best,
        relaxed=_middle([f.relaxed for f in plausible]),
        relaxed_low=min(_values(plausible, "relaxed_low")),
        relaxed_high=max(_values(plausible, "relaxed_high")),
        instantaneous=_middle([f.instantaneous for f in plausible]),
        instantaneous_low=min(_values(plausible, "instantaneous_low")),
        instantaneous_high=max(_values(plausible, "instantaneous_high")),
        warnings=best.warnings + checked,
        hypotheses=len(fits),
        plausible=len(plausible),
    )


def _contradictions(
    record: RelaxationRecord,
    belief: Belief,
    stated: Hypothesis,
    at: tuple[tuple[float, float, float], float],
    fit: RelaxationFit,
) -> tuple[str, ...]:
    """The belief check on the relaxed curve (none or one sentence): each alternative to the
    belief's point properties around the best hypothesis (``jointfit.beliefcheck``), its
    lowest RSS against the best's, in its noise variances, past ``MARGIN``. Only where the
    record relaxes: an elastic record's check is the joint fit's."""
    if not fit.relaxes or fit.rss is None:
        return ()
    contact, modulus = at
    shifted = _less_compliance(record, stated.compliance)
    gains = {
        what: (fit.rss - floor_rss(shifted, law, contact, modulus)) / (fit.noise_scale or 1.0)
        for what, law in alternatives(belief, stated.law)
    }
    return contradiction(gains, MARGIN, "the relaxed record")


def thinned(hypotheses: Sequence[Hypothesis], per_axis: int = PER_AXIS) -> list[Hypothesis]:
    """The hypotheses at most ``per_axis`` values of each property apart: each axis's ends and
    the values nearest evenly between (an unknown thickness's grid has up to 51, and a fit a
    hypothesis costs tens of ms; E moves monotonically along each axis, so the ends carry the
    envelope and the inner points the middle)."""
    points = [_axes(h) for h in hypotheses]
    kept = []
    for axis in range(4):
        values = sorted({p[axis] for p in points})
        picks = np.unique(np.round(np.linspace(0, len(values) - 1, min(per_axis, len(values)))))
        kept.append({values[int(i)] for i in picks})
    return [
        h
        for h, p in zip(hypotheses, points, strict=True)
        if all(v in k for v, k in zip(p, kept, strict=True))
    ]


def _axes(h: Hypothesis) -> tuple[float, float, float, float]:
    """A hypothesis's thickness (0: the half-space), base, Poisson ratio and compliance."""
    return (h.law.thickness or 0.0, float(h.law.bonded), h.law.poisson, h.compliance)


def allowance(record: RelaxationRecord, model_form: float) -> float:
    """What a relative bias ``model_form`` of the law is worth in weighted RSS on ``record``:
    ``sum (eps P_i / sigma_P,i)^2`` over the loaded samples (the load's noise alone: an upper
    bound, the depth's noise only adds to sigma)."""
    loaded = record.load > 0.0
    return float(np.sum((model_form * record.load[loaded] / record.sigma_load[loaded]) ** 2))


def _less_compliance(record: RelaxationRecord, compliance: float) -> RelaxationRecord:
    if compliance == 0.0:
        return record
    return dataclasses.replace(record, depth_base=record.depth_base - compliance * record.load)


def _values(fits: Sequence[RelaxationFit], name: str) -> list[float]:
    return [float(v) for f in fits if (v := getattr(f, name)) is not None]


def _middle(values: Sequence[float | None]) -> float:
    known = [float(v) for v in values if v is not None]
    return 0.5 * (min(known) + max(known))
