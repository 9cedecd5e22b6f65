"""The joint fit's result, and the failure a step of the fit raises to end it early."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .pooling import Terms


@dataclass(frozen=True)
class JointFit:
    """Result of :func:`estimation.jointfit.joint_fit`; moduli in Pa, positions in m.

    Attributes:
        success: True when E and x0 were fitted (check ``warnings`` too).
        message: "ok" or what failed.
        modulus: E, or None on failure.
        contact: x0, the stage position at contact.
        load_offset: P0 (N), the fitted constant load offset (0 when not fitted).
        ci_low, ci_high: the confidence interval of E at ``confidence``.
        contact_low, contact_high: the same for x0.
        confidence: the interval's level.
        n_points: samples used; n_contact: those with delta > 0 at the solution.
        max_depth: the largest fitted indentation delta.
        rms: rms of the standardised residuals (about 1 when the noise model holds).
        rho: their lag-1 autocorrelation past contact, capped at ``jointfit.noise.MAX_RHO``
            (the model misses part of the curve where it is high).
        noise_scale: s, the factor the nominal noise was inflated by for the interval.
        model_spread: |E(other layer ratio) - E| (Pa), each form fitted with its own x0 and P0
            (0 for a half-space); the interval is the envelope of both forms' intervals.
        model_form: eps, the relative model-form bound combined into the interval
            (``jointfit.modelform``).
        profiled: the belief's properties the interval was profiled over (``thickness``,
            ``bonded``, ``poisson``, ``compliance``), besides the contact and load offset.
        hypotheses: how many points of the belief's grid were profiled.
        best: the best-fitting hypothesis (``estimation.belief.Hypothesis.describe``: thickness
            m or None, bonded, poisson, compliance m/N), the one the estimate is fitted with.
        nfev: residual evaluations of the refinement.
        law: the contact law's name.
        warnings: validity flags and fit diagnostics, one sentence each.
    """

    success: bool
    message: str
    modulus: float | None = None
    contact: float | None = None
    load_offset: float | None = None
    ci_low: float | None = None
    ci_high: float | None = None
    contact_low: float | None = None
    contact_high: float | None = None
    confidence: float = 0.95
    n_points: int = 0
    n_contact: int = 0
    max_depth: float | None = None
    rms: float | None = None
    rho: float = 0.0
    noise_scale: float | None = None
    model_spread: float | None = None
    model_form: float | None = None
    profiled: tuple[str, ...] = ()
    hypotheses: int = 0
    best: dict[str, object] | None = None
    nfev: int = 0
    law: str = ""
    warnings: tuple[str, ...] = field(default=())
    # the trial's share of its sample's pooled fit (``jointfit.pooling``): in memory only
    terms: Terms | None = field(default=None, compare=False, repr=False)

    def covers(self, modulus: float) -> bool:
        """Whether the interval [ci_low, ci_high] holds ``modulus`` (Pa); False without one."""
        return (
            self.ci_low is not None
            and self.ci_high is not None
            and (self.ci_low <= modulus <= self.ci_high)
        )

    def as_dict(self) -> dict[str, object]:
        """JSON-ready fields (SI units, as named)."""
        return {
            "success": self.success,
            "message": self.message,
            "modulus": self.modulus,
            "contact": self.contact,
            "load_offset": self.load_offset,
            "ci_low": self.ci_low,
            "ci_high": self.ci_high,
            "contact_low": self.contact_low,
            "contact_high": self.contact_high,
            "confidence": self.confidence,
            "n_points": self.n_points,
            "n_contact": self.n_contact,
            "max_depth": self.max_depth,
            "rms": self.rms,
            "noise_scale": self.noise_scale,
            "model_spread": self.model_spread,
            "model_form": self.model_form,
            "profiled": list(self.profiled),
            "hypotheses": self.hypotheses,
            "best": self.best,
            "nfev": self.nfev,
            "law": self.law,
            "warnings": list(self.warnings),
        }


class FitFailed(Exception):  # noqa: N818 - a result, not an error: it becomes success False
    """A step of the joint fit found no answer; the message names the step and why.

    Not a ValueError: bad input raises that and goes to the caller, while this ends the recipe
    early and becomes a :class:`JointFit` with ``success`` False (:meth:`result`).

    Attributes:
        message: what failed ("no contact: ...", "least squares did not converge: ...").
        n_contact: samples past the contact point when the step failed (0 if not known yet).
        nfev: residual evaluations of the refinement so far.
    """

    def __init__(self, message: str, n_contact: int = 0, nfev: int = 0) -> None:
        super().__init__(message)
        self.message = message
        self.n_contact = n_contact
        self.nfev = nfev

    def result(self, n_points: int, confidence: float, law: str) -> JointFit:
        """The failed fit as the caller sees it (``law``: the contact law's name)."""
        return JointFit(
            False,
            self.message,
            n_points=n_points,
            n_contact=self.n_contact,
            nfev=self.nfev,
            confidence=confidence,
            law=law,
        )
