"""Each trial's verdict on its estimate: ``ok``, ``suspect`` (with reasons) or ``none`` (why).

A number is only as good as what it assumed. The verdict reads the joint fit
(``estimation.jointfit``) and what the trial itself knows (:class:`TrialFacts`):

- ``none`` (no number): the fit failed (its message says which step and why), or the tissue is
  too soft for this sensor: the trial used up its travel window without buckling, or the fitted
  modulus needs more indentation than the window to reach P_cr (the sensor then measures outside
  the range it was designed for; ``palpate design`` designs one for the range).
- ``suspect`` (a number, not to be counted as good): the interval is wider than IMPRECISE either
  side of the estimate (what the belief leaves open, e.g. a thickness range, leaves the modulus
  undetermined: a number to report with its interval, not on its own), the contact's interval
  reaches the record's edge, the contact lies before the record, the residuals are correlated
  (the model misses part of the curve), a validity flag the law does not correct (thin-layer
  series extrapolated, misalignment past 5 deg), the misalignment beyond the campaign's
  tolerance, an uncalibrated compliance (the interval was widened over its plausible range),
  or a trial that did not end ``done``, or a hold that shows the tissue relaxing (the elastic
  number then depends on the indentation speed; the relaxation fit's own verdict,
  :func:`relaxed_verdict`, judges the relaxed modulus).
- ``ok``: none of these.

Tables count trials per verdict, take medians over ``ok`` only, and the interval's coverage over
every trial with a number (``ok`` and ``suspect``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

from .jointfit import JointFit
from .jointfit.beliefcheck import CONTRADICTED
from .jointfit.envelope import BEFORE_WARNING, CORRELATED_WARNING, EDGE_WARNING
from .pose.heartbeat import Heartbeat
from .pose.misalignment import Lean
from .reach import Reach, too_soft
from .relaxation import RelaxationFit

Status = Literal["ok", "suspect", "none"]
STATUSES: tuple[Status, ...] = ("ok", "suspect", "none")
CORRECTED = ("corrected with", "correction applied")
NORMAL_SIGMAS = 2.0  # a measured misalignment is within the tolerance when this many sigmas are
IMPRECISE = 0.10
"""Relative half-width of the 95 % interval beyond which a number is not ``ok``. Where the
interval is what a belief leaves open (a thickness range, Poisson's ratio), the truth may lie
anywhere in it and the estimate sits near its middle: a typical error of half the half-width.
``ok`` promises a typical error of 5 % (the issue's accuracy target), so +-10 %; +-15 % let
through numbers 12-13 % off (5 mm layers believed 5-20 mm) that their intervals still held."""


@dataclass(frozen=True)
class Verdict:
    """``status`` and its reasons (one sentence each; empty for ``ok``)."""

    status: Status
    reasons: tuple[str, ...] = ()

    @property
    def has_number(self) -> bool:
        return self.status != "none"

    def as_dict(self) -> dict[str, object]:
        return {"status": self.status, "reasons": list(self.reasons)}

    @classmethod
    def from_dict(cls, d: dict[str, object]) -> Verdict:
        status = d.get("status")
        reasons = d.get("reasons") or []
        if status not in STATUSES or not isinstance(reasons, list | tuple):
            raise ValueError(f"a verdict is {{status: one of {STATUSES}, reasons: [...]}}, got {d}")
        return cls(STATUSES[STATUSES.index(status)], tuple(str(r) for r in reasons))


@dataclass(frozen=True)
class TrialFacts:
    """What the trial knows besides the fit (SI).

    Attributes:
        state, reason: how the trial ended (``robot.indentation.State`` value and its reason).
        travel_window: the travel past contact allowed before a fault (m), None if unknown.
        critical_load: the beam's P_cr at the contact's exposed length (N), None if unknown.
        misalignment: angle between the sensor axis and the surface normal (rad), if known.
        misalignment_tolerance: the campaign's tolerance on it (rad), None: not checked.
        compliance_calibrated: the rig's compliance was calibrated (else profiled over a range).
        orientation_verified: the misalignment was measured (probing's fitted normal) or set
            by the operator (no probing); False when probing could not measure a normal.
        lean: the load's lean measured from the strains (``estimation.pose.misalignment``).
        misalignment_sigma: the measured normal's 1-sigma angle (rad), None if not measured.
        relaxation: the relaxation fit of a trial that held (``estimation.relaxation``).
        designed_range: the moduli (Pa) the sensor was designed for, None: not stated.
        buckling_tip_load: the tip grating's load at the buckling mark (N), None without one.
        bow: the beam's bow w0/L fitted against the tip grating's load (Southwell), None
            without one (a bow fitted against the strains' own load is not independent).
        probe_reason: what probing said when it measured no normal, None if not known.
        motion: the surface's displacement along the axis between the first touch and the
            release (m, ``estimation.pose.motion``), None if not measured.
        motion_tolerance: the campaign's tolerance on it (m), None: not checked.
        poisson, compliance_max: the believed Poisson ratio and the rig's largest compliance
            (m/N): with them a trial whose window ran out bounds the modulus (``reach``).
        heart: the heart's beat taken out of the record (``estimation.pose.heartbeat``), None.
    """

    state: str = "done"
    reason: str = ""
    travel_window: float | None = None
    critical_load: float | None = None
    misalignment: float | None = None
    misalignment_tolerance: float | None = None
    compliance_calibrated: bool = True
    orientation_verified: bool = True
    lean: Lean | None = None
    misalignment_sigma: float | None = None
    relaxation: RelaxationFit | None = None
    designed_range: tuple[float, float] | None = None
    buckling_tip_load: float | None = None
    bow: float | None = None
    probe_reason: str | None = None
    motion: float | None = None
    motion_tolerance: float | None = None
    poisson: float | None = None
    compliance_max: float | None = None
    heart: Heartbeat | None = None


HOLDS_RAN_OUT = "no estimate: every breath hold ended before the trial did"
"""How a gated trial ends when its last allowed breath hold ended before it (robot.body)."""
MOTION_SHARE = 0.04
"""The surface's motion during a contact, as a share of the fitted indentation, past which the
trial is not ok (with ``motion_tolerance`` set): about 6 % of the modulus (docs/breathing.md)."""
EARLY_BUCKLING = 0.5
"""A buckling mark at a tip load below this share of P_cr was not the tissue's buckling."""
BOW_LIMIT = 0.01
"""The bow w0/L past which the shortening read as a straight beam's is not trusted: the bow's
share of the shortening, 2 z0 z L, is first order in the bending and left out
(``estimation.fits.southwell``); docs/lung.md measures it (w0/L 4-5 %: -9 to -27 %)."""


def judge(fit: JointFit | None, facts: TrialFacts, tip_radius: float) -> Verdict:
    """The verdict on ``fit`` (None: no fit was made) for a trial with ``facts``; ``tip_radius``
    (m) is the sensor's, for the depth buckling needs."""
    reach = Reach(facts.travel_window, facts.critical_load, facts.poisson, facts.compliance_max)
    soft = too_soft(fit, facts.reason, reach, tip_radius)
    if soft is not None or facts.reason.startswith(HOLDS_RAN_OUT):
        return _none(soft or facts.reason, facts)
    if fit is None or not fit.success or fit.modulus is None:
        return _none("no estimate: " + ("no fit" if fit is None else fit.message), facts)
    # outside the designed range: still a number and its interval, marked suspect (a clinician's
    # answer to 0.8 kPa before a 1-20 kPa sensor is "softer than 1 kPa", not nothing)
    # -- unless the tip slid: its load never reached the pinned beam's, so the number is the
    # slide's, not the tissue's (none, naming the slide)
    outside = _outside_range(fit, facts.designed_range)
    if outside is not None and facts.lean is not None and facts.lean.lateral:
        return _none(outside, facts)
    reasons = [] if outside is None else [outside]
    reasons += [w for w in fit.warnings if _is_suspect(w) and not _relaxation_explains(w, facts)]
    imprecise = _imprecise(fit)
    if imprecise is not None:
        reasons.append(imprecise)
    reasons += _trial_reasons(facts)
    reasons += [why for why in (_moved(fit, facts), _beat(facts)) if why is not None]
    if facts.relaxation is not None and facts.relaxation.relaxes:
        reasons += [w for w in facts.relaxation.warnings if w.startswith(CONTRADICTED)]
        reasons.append(
            f"{facts.relaxation.summary()}: the elastic estimate is an apparent modulus at this "
            "indentation speed, between the two; the relaxed modulus is the tissue's long-time one"
        )
    return Verdict("suspect", tuple(reasons)) if reasons else Verdict("ok")


def _none(reason: str, facts: TrialFacts) -> Verdict:
    """No number, for ``reason``; a tip that slid says so too (its load never reached the
    pinned beam's, which may be why)."""
    lean = facts.lean
    slid = tuple(_orientation(facts)) if lean is not None and lean.lateral else ()
    return Verdict("none", (reason, *slid))


def _outside_range(fit: JointFit, designed: tuple[float, float] | None) -> str | None:
    """Why a modulus whose whole interval lies outside the sensor's designed range is suspect
    (its number kept: which side of the range it lies is the answer), or None."""
    if designed is None or fit.modulus is None:
        return None
    lo = fit.modulus if fit.ci_low is None else fit.ci_low
    hi = fit.modulus if fit.ci_high is None else fit.ci_high
    if lo <= designed[1] and hi >= designed[0]:
        return None
    side = "below" if hi < designed[0] else "above"
    return (
        f"{side} the designed range {designed[0] / 1e3:g}-{designed[1] / 1e3:g} kPa: "
        f"{fit.modulus / 1e3:.3g} kPa, outside the sensor's designed range, less accurate "
        "there (see `palpate design`)"
    )


def _early_buckling(facts: TrialFacts) -> str | None:
    """Why a buckling mark at a small tip load (a tip grating's) was not the tissue's, or None."""
    load, p_cr = facts.buckling_tip_load, facts.critical_load
    if load is None or p_cr is None or load >= EARLY_BUCKLING * p_cr:
        return None
    return (
        f"buckling detected at a tip load of {load * 1e3:.3g} mN, {load / p_cr:.0%} of the beam's "
        f"critical load ({p_cr * 1e3:.3g} mN): the beam bent under something else than the "
        "tissue (its own weight across it, a bow), not the straight beam's buckling"
    )


def _trial_reasons(facts: TrialFacts) -> list[str]:
    """Why any number of this trial is suspect, whatever the model: the rig's compliance, the
    misalignment and orientation, how the trial ended."""
    reasons: list[str] = []
    if not facts.compliance_calibrated:
        reasons.append(
            "the rig's compliance is not calibrated: the interval spans its plausible range "
            "(calibrate on a rigid reference: `palpate calibrate`)"
        )
    tol, mis = facts.misalignment_tolerance, facts.misalignment
    if tol is not None and mis is not None and abs(mis) > tol:
        reasons.append(
            f"misalignment {math.degrees(abs(mis)):.1f} deg beyond the campaign's tolerance "
            f"of {math.degrees(tol):g} deg"
        )
    reasons.extend(_orientation(facts))
    early = _early_buckling(facts)
    if early is not None:
        reasons.append(early)
    if facts.bow is not None and abs(facts.bow) > BOW_LIMIT:
        reasons.append(
            f"the beam is bowed before it buckles, w0/L = {abs(facts.bow):.1%} against the tip "
            f"grating's load (its own weight across it, or a crooked beam): past "
            f"{BOW_LIMIT:.0%} the shortening read as a straight beam's is not trusted"
        )
    if facts.state != "done":
        reasons.append(f"the trial ended in {facts.state}: {facts.reason}")
    return reasons


def _moved(fit: JointFit, facts: TrialFacts) -> str | None:
    """Why the surface's motion during the contact (``facts.motion``) is too much, None if it
    is not (or is not checked): past the campaign's tolerance, or past MOTION_SHARE of the
    fitted indentation (the modulus moves by about 1.5 times that share); with a tolerance and
    no motion measured, that it is not known."""
    moved, tol = facts.motion, facts.motion_tolerance
    if tol is None:
        return None
    if moved is None:  # a campaign that expects motion cannot vouch for a trial it did not see
        return (
            "motion not measured: the first touch and the release could not be matched at one "
            f"load, so whether the surface moved past the {tol * 1e3:g} mm tolerance is not known"
        )
    limit, what = tol, f"the campaign's {tol * 1e3:g} mm tolerance"
    if fit.max_depth is not None and MOTION_SHARE * fit.max_depth < limit:
        limit = MOTION_SHARE * fit.max_depth
        what = f"{MOTION_SHARE:.0%} of the {fit.max_depth * 1e3:.2f} mm indentation"
    if abs(moved) <= limit:
        return None
    toward = "toward" if moved > 0 else "away from"
    return (
        f"moved: the surface moved {abs(moved) * 1e3:.2f} mm {toward} the sensor between the "
        f"first touch and the release, over {what} ("
        + ("a drift: breathing, the patient)" if facts.heart else "breathing, the heart?)")
    )


def _beat(facts: TrialFacts) -> str | None:
    """That the heart moved the surface past the campaign's tolerance, taken out of the record
    (the interval carries its amplitude's error), or None."""
    heart, tol = facts.heart, facts.motion_tolerance
    if heart is None or tol is None or 2.0 * heart.amplitude <= tol:
        return None
    return (
        f"heartbeat: the surface beat {2e3 * heart.amplitude:.2f} mm peak to peak every "
        f"{heart.period:.2f} s (the ECG's R waves), past the {tol * 1e3:g} mm tolerance; taken "
        "out of the record, its amplitude's error carried in the interval"
    )


def _orientation(facts: TrialFacts) -> list[str]:
    """Why the sensor's orientation to the surface is not known to be square (empty if it is)."""
    lean = facts.lean
    if lean is not None and lean.lateral:
        slid = (
            f"the strains show a lateral load from the first touch (the tip slid on a surface "
            f"oblique beyond its friction angle; a pinned tip fits {lean.aligned_chi2:.0f} noise "
            f"variances worse)"
        )
        if not lean.measured:
            return [f"misaligned: {slid}; its angle was not measured ({lean.message})"]
        return [
            f"misaligned: misalignment {math.degrees(lean.misalignment):.1f} +- "
            f"{math.degrees(lean.misalignment_sigma):.1f} deg measured from the strains and the "
            f"stage (the slipping tip's path; a slide off the fiber's plane reads high); {slid}"
        ]
    if facts.orientation_verified:
        return _within_tolerance(facts)
    seen = "not measured" if lean is None or not lean.success else "none"
    why = "a straight tube's touches all lie on one line"
    reason = facts.probe_reason
    if reason is not None and "straight tube" not in reason:
        why = f"probing: {reason}"
    return [
        f"orientation unverified: no normal was measured ({why}) and the strains show no "
        f"lateral load ({seen}), which a sticking contact gives at any tilt within its friction "
        f"angle"
    ]


def _within_tolerance(facts: TrialFacts) -> list[str]:
    """Why a measured misalignment within the tolerance is not known to be (empty if it is):
    the measured normal's ``NORMAL_SIGMAS`` sigmas take it past the tolerance."""
    tol, mis, sigma = facts.misalignment_tolerance, facts.misalignment, facts.misalignment_sigma
    if tol is None or mis is None or sigma is None or not math.isfinite(sigma):
        return []
    if abs(mis) > tol or abs(mis) + NORMAL_SIGMAS * sigma <= tol:
        return []
    return [
        f"misalignment {math.degrees(abs(mis)):.1f} +- {math.degrees(sigma):.1f} deg (the "
        f"measured normal's 1-sigma): not verified within the campaign's tolerance of "
        f"{math.degrees(tol):g} deg at {NORMAL_SIGMAS:g} sigmas"
    ]


def _imprecise(fit: JointFit) -> str | None:
    """Why the interval is too wide for "ok", or None."""
    opened = f" (profiled over {', '.join(fit.profiled)})" if fit.profiled else ""
    what = f"the {round(100 * fit.confidence)} % interval"
    return _wider_than_imprecise(what, fit.modulus, fit.ci_low, fit.ci_high, opened)


def _wider_than_imprecise(
    what: str, value: float | None, lo: float | None, hi: float | None, note: str = ""
) -> str | None:
    """Why ``what``, [lo, hi] about ``value``, is too wide for "ok" (beyond ``IMPRECISE`` on
    either side), or None."""
    if value is None or lo is None or hi is None or value <= 0:
        return None
    down, up = (value - lo) / value, (hi - value) / value
    if max(down, up) <= IMPRECISE:
        return None
    return (
        f"imprecise: {what} spans -{100 * down:.0f} % / +{100 * up:.0f} %{note}, "
        f"beyond +-{100 * IMPRECISE:.0f} %"
    )


def _relaxation_explains(warning: str, facts: TrialFacts) -> bool:
    """Whether ``warning`` is the elastic belief check's on a record that relaxes: the elastic
    law's misfit is then the relaxation's, which a thicker layer or a softer base mimics (on
    relaxing lung-like layers it blamed the thickness in 39 of 72 trials with true beliefs);
    the check on the relaxed curve (``estimation.relaxation.beliefs``) replaces it."""
    relaxes = facts.relaxation is not None and facts.relaxation.relaxes
    return relaxes and warning.startswith(CONTRADICTED)


def _is_suspect(warning: str) -> bool:
    if warning.startswith((EDGE_WARNING, BEFORE_WARNING, CORRELATED_WARNING)):
        return True
    return not any(c in warning for c in CORRECTED)


def relaxed_verdict(
    fit: RelaxationFit | None, elastic: Verdict, facts: TrialFacts
) -> Verdict | None:
    """The verdict on the relaxed modulus of a trial that held (None without a hold): ``none``
    without a fit or without a number from the trial; ``suspect`` where the relaxation is not
    complete within the record (the modulus is extrapolated), the interval is wider than
    ``IMPRECISE``, or the trial has a reason of its own (a
    misalignment, an unverified orientation, a trial that did not end ``done``: they concern the
    relaxed number as much; the elastic fit's own misfit, which relaxation causes, does not);
    else ``ok``. An elastic record (no relaxation) says so, and its
    relaxed modulus is the elastic one."""
    if fit is None:
        return None
    if not fit.success or fit.relaxed is None or not elastic.has_number:
        why = fit.message if not fit.success else "no elastic estimate to start from"
        return Verdict("none", (f"no relaxed modulus: {why}",))
    reasons = _trial_reasons(facts) + list(fit.warnings)
    what = "the relaxed modulus's interval"
    wide = _wider_than_imprecise(what, fit.relaxed, fit.relaxed_low, fit.relaxed_high)
    if wide is not None:
        reasons.append(wide)
    return Verdict("suspect", tuple(reasons)) if reasons else Verdict("ok")
