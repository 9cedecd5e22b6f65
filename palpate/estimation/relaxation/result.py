"""The relaxation fit's input record and its result (``estimation.relaxation``)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class RelaxationFit:
    """What :func:`fit_relaxation` found (Pa, s).

    Attributes:
        success, message: whether the moduli were fitted ("ok"), else why not.
        relaxed, relaxed_low, relaxed_high: E_inf and its interval.
        instantaneous, instantaneous_low, instantaneous_high: E_0 and its interval.
        relaxation_time: the spectrum's mean time sum c_k tau_k / sum c_k (None: no relaxation).
        relaxes: the record shows relaxation (see the module docstring).
        complete: the relaxation is over within the record (False: E_inf is extrapolated).
        delta_chi2: how much better the spectrum fits than the elastic law (noise variances).
        hold: the hold's length (s); n_points: samples fitted; contact: x0 (m).
        warnings: one sentence each.
        hypotheses: how many of the belief's hypotheses were fitted; plausible: how many of them
            the record allows (within the chi^2 quantile and the model-form allowance), whose
            intervals the moduli's are the envelope of (``estimation.relaxation.beliefs``).
        rss, noise_scale: the lowest weighted RSS over the contact (the spectrum reaching past
            the record) and the noise inflation, for comparing hypotheses (not in
            :meth:`as_dict`, nor compared: a fit read back from a log is the same fit).
    """

    success: bool
    message: str
    relaxed: float | None = None
    relaxed_low: float | None = None
    relaxed_high: float | None = None
    instantaneous: float | None = None
    instantaneous_low: float | None = None
    instantaneous_high: float | None = None
    relaxation_time: float | None = None
    relaxes: bool = False
    complete: bool = True
    delta_chi2: float | None = None
    hold: float = 0.0
    n_points: int = 0
    contact: float | None = None
    confidence: float = 0.95
    warnings: tuple[str, ...] = field(default=())
    hypotheses: int = 1
    plausible: int = 1
    rss: float | None = field(default=None, compare=False, repr=False)
    noise_scale: float | None = field(default=None, compare=False, repr=False)

    def covers(self, modulus: float) -> bool:
        """Whether the relaxed modulus's interval holds ``modulus`` (Pa)."""
        lo, hi = self.relaxed_low, self.relaxed_high
        return lo is not None and hi is not None and lo <= modulus <= hi

    def as_dict(self) -> dict[str, object]:
        return {
            "success": self.success,
            "message": self.message,
            "relaxed": self.relaxed,
            "relaxed_low": self.relaxed_low,
            "relaxed_high": self.relaxed_high,
            "instantaneous": self.instantaneous,
            "instantaneous_low": self.instantaneous_low,
            "instantaneous_high": self.instantaneous_high,
            "relaxation_time": self.relaxation_time,
            "relaxes": self.relaxes,
            "complete": self.complete,
            "delta_chi2": self.delta_chi2,
            "hold": self.hold,
            "n_points": self.n_points,
            "contact": self.contact,
            "confidence": self.confidence,
            "warnings": list(self.warnings),
            "hypotheses": self.hypotheses,
            "plausible": self.plausible,
        }

    def summary(self) -> str:
        """One sentence for a verdict or a table."""
        if not self.success or self.relaxed is None:
            return f"relaxation not estimated: {self.message}"
        if not self.relaxes:
            return f"no relaxation in the {self.hold:g} s hold"
        tau = "" if self.relaxation_time is None else f", mean time {self.relaxation_time:.2g} s"
        return (
            f"relaxes in the hold ({self.hold:g} s: E_0 {_kpa(self.instantaneous)}, relaxed "
            f"{_kpa(self.relaxed)} [{_kpa(self.relaxed_low)}, {_kpa(self.relaxed_high)}]{tau})"
        )


def _kpa(v: float | None) -> str:
    return "-" if v is None else f"{v / 1e3:.0f} kPa"


@dataclass(frozen=True)
class RelaxationRecord:
    """The record the fit reads (every array (N,), SI): times t, the load from the strains
    less the joint fit's offset, ``u - e - c P`` (the depth plus x0) and the noise model's
    standard deviations of the load and of the depth."""

    times: FloatArray
    load: FloatArray
    depth_base: FloatArray
    sigma_load: FloatArray
    sigma_depth: FloatArray
    hold: float
