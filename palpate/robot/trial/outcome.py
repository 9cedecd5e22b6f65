"""One outcome type for a finished trial, on the bench and in simulation: how it ended and what it
estimated, with one serialisation of the estimates (``robot.trial.record.estimate_row``).

The simulator's ``TrialOutcome`` and the bench's ``BenchOutcome`` are this type with their own
context beside it (the campaign's trial spec and IK residual; the bench file's planned trial
and the bus counters)::

    done = run_session_trial(rig, clock, setup)
    fields = outcome_fields(done.result, done.estimate, done.log_path)
    outcome = BenchOutcome(trial, **fields)
    outcome.modulus("joint"), outcome.status, outcome.estimate_row()
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ...estimation.fits.compliance import ComplianceFit
from ...estimation.fits.southwell import SouthwellFit
from ...estimation.fits.stiffness import StiffnessEstimate
from ...estimation.jointfit import JointFit
from ...estimation.pose.misalignment import Lean
from ...estimation.relaxation import RelaxationFit
from ...estimation.trial.estimate import TrialEstimate
from ...estimation.verdict import Verdict
from ..plan import State, TrialMarks
from .record import estimate_row
from .run import TrialResult

if TYPE_CHECKING:  # the maps' package imports scikit-learn: not at a trial's start-up
    from ...maps.probes import Probe


@dataclass(kw_only=True)
class Outcome:
    """A finished trial (keyword fields: its context's come first in the subclasses).

    Attributes:
        state, reason: how it ended (a terminal ``robot.plan.State``, or ``SKIPPED``) and why.
        log_path: its log (None: none written); marks: encoder at contact and at buckling.
        estimate: the paper's single point (Eqs. 13-14); exposed_length_at_buckling: L (m).
        joint: the joint fit (the headline estimate); verdict: ok, suspect or none, with
            reasons; southwell: the beam's bow; calibration: on a rigid reference, the rig's
            compliance instead; lean: the load's lean; relaxation and relaxed_verdict: a hold's.
    """

    state: State
    reason: str
    log_path: str | None = None
    marks: TrialMarks | None = None
    estimate: StiffnessEstimate | None = None
    exposed_length_at_buckling: float | None = None
    joint: JointFit | None = None
    joint_seconds: float | None = None  # wall time of the joint fit (for reports, not tests)
    verdict: Verdict | None = None
    southwell: SouthwellFit | None = None
    calibration: ComplianceFit | None = None
    lean: Lean | None = None
    relaxation: RelaxationFit | None = None
    relaxed_verdict: Verdict | None = None
    motion: float | None = None  # m, the surface's along the axis (estimation.pose.motion)
    heart: float | None = None  # m, the heart's beat peak to peak (estimation.pose.heartbeat)

    @property
    def status(self) -> str:
        """The verdict's status ("none" without one)."""
        return "none" if self.verdict is None else self.verdict.status

    def modulus(self, method: str = "joint") -> float | None:
        """E (Pa) by ``"joint"`` (the whole-record fit; None when its verdict is ``none``) or
        ``"paper"`` (Eqs. 13-14)."""
        if method == "joint":
            if self.joint is None or self.status == "none":
                return None
            return self.joint.modulus
        if method == "paper":
            return None if self.estimate is None else self.estimate.modulus
        raise ValueError(f"method must be 'joint' or 'paper', got {method!r}")

    def estimate_row(self) -> dict[str, Any]:
        """The row's estimate keys (``robot.trial.record.estimate_row``)."""
        return estimate_row(self)


def outcome_fields(
    result: TrialResult, estimate: TrialEstimate, log_path: str | None
) -> dict[str, Any]:
    """The :class:`Outcome` fields of a trial the session ran (keywords for its subclasses)."""
    return {
        "state": result.state,
        "reason": result.reason,
        "log_path": log_path,
        "marks": result.marks,
        "estimate": estimate.paper,
        "exposed_length_at_buckling": estimate.exposed_length_at_buckling,
        "joint": estimate.joint,
        "joint_seconds": estimate.joint_seconds,
        "verdict": estimate.verdict,
        "southwell": estimate.southwell,
        "calibration": estimate.calibration,
        "lean": estimate.lean,
        "relaxation": estimate.relaxation,
        "relaxed_verdict": estimate.relaxed_verdict,
        "motion": estimate.motion,
        "heart": estimate.heart,
    }


def probe_of(
    o: Outcome, point: tuple[float, float], lab_time: float, tip_radius: float | None = None
) -> Probe:
    """A finished trial as a map's probe at ``point`` (m): the joint fit's modulus and interval
    when it succeeded, the verdict's status and reasons (the trial's end when it has none), the
    lab time it took (s, with the stage's travel to it) and, given the sensor's ``tip_radius``
    (m), the contact's radius at the fit's deepest point, sqrt(R delta)."""
    from ...maps.probes import Probe

    jf, v = o.joint, o.verdict
    ok = jf is not None and jf.success and jf.modulus is not None
    ci = None
    if ok and jf is not None and jf.ci_low is not None and jf.ci_high is not None:
        ci = (jf.ci_low, jf.ci_high)
    reasons = () if v is None else tuple(v.reasons) or (() if ok else (o.reason,))
    if o.state == State.UNREACHABLE:  # why it never indented, before what the fit then said
        reasons = (o.reason, *reasons)
    return Probe(
        point[0],
        point[1],
        jf.modulus if ok and jf is not None else None,
        ci,
        "none" if v is None else v.status,
        reasons,
        lab_time,
        _contact_radius(jf, tip_radius) if ok else None,
    )


def _contact_radius(jf: JointFit | None, tip_radius: float | None) -> float | None:
    """sqrt(R delta) at the fit's deepest point (m), None without a tip radius or a depth."""
    depth = None if jf is None else jf.max_depth
    if tip_radius is None or depth is None or depth <= 0.0:
        return None
    return math.sqrt(tip_radius * depth)
