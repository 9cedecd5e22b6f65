"""A campaign killed mid-way, resumed: the outcome of a finished trial read back from its log.

A complete log (header, samples, estimate, end) holds everything a trial's row in the tables
needs: the final state and reason, the marks, the paper's estimate and the joint fit (floats
written at ``repr`` precision, so they read back bit for bit). What the log does not hold is
recomputed exactly as the trial computed it (the IK residual from the spec's geometry, the
exposed length at buckling from the marks). A log that is not complete, is damaged or belongs
to another trial gives None: that trial runs again.
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path
from typing import Any, TypeVar

from palpate.campaigns.runs import set_aside
from palpate.campaigns.shorter import chained
from palpate.config.scene import CampaignConfig
from palpate.config.schema import StackConfig
from palpate.estimation.fits.compliance import ComplianceFit
from palpate.estimation.fits.southwell import SouthwellFit
from palpate.estimation.fits.stiffness import StiffnessEstimate
from palpate.estimation.jointfit import JointFit
from palpate.estimation.jointfit.pooling import Terms
from palpate.estimation.pose.misalignment import Lean
from palpate.estimation.relaxation import RelaxationFit
from palpate.robot.indentation import TrialMarks
from palpate.robot.plan import State
from palpate.robot.probe_result import ProbeResult, Touch
from palpate.robot.records.log import TrialLog, TrialLogError, read_log
from palpate.robot.trial.record import recorded_verdict
from palpate.simulation.result import trial_stage
from palpate.simulation.trial import TrialOutcome, TrialSpec, trial_geometry

T = TypeVar("T")


def resume_outcomes(
    log_dir: Path,
    specs: list[TrialSpec],
    stack: StackConfig,
    campaign: CampaignConfig | None = None,
) -> dict[str, TrialOutcome]:
    """The outcomes of ``specs`` whose logs in ``log_dir`` are complete, by trial id; a log
    that cannot stand for its trial (killed mid-trial, damaged) is moved aside (``runs``).
    With ``campaign``, a trial that buckled unread is done only where its retries at shorter
    lengths (``campaigns.shorter``) are, as far as they went: the last one stands for it."""
    done: dict[str, TrialOutcome] = {}

    def logged(attempt: TrialSpec) -> TrialOutcome | None:
        return logged_outcome(log_dir, attempt, stack)

    for spec in specs:
        outcome = logged(spec) if campaign is None else chained(spec, campaign, logged)
        if outcome is not None:
            done[spec.trial_id] = outcome
    return done


def logged_outcome(log_dir: Path, spec: TrialSpec, stack: StackConfig) -> TrialOutcome | None:
    """``spec``'s outcome from its log in ``log_dir``; None without one that can stand for it
    (a damaged one moved aside). A resumed chain of retries reads its attempts that finished
    with this, and runs the rest."""
    path = log_dir / f"{spec.trial_id}.jsonl"
    if not path.exists():
        return None
    outcome = outcome_from_log(path, spec, stack)
    if outcome is None:
        set_aside(path)
    return outcome


def outcome_from_log(path: Path, spec: TrialSpec, stack: StackConfig) -> TrialOutcome | None:
    """``spec``'s outcome as its trial returned it, from its log at ``path`` (``stack``: the
    campaign's robot); None when the log cannot stand for the trial."""
    try:
        log = read_log(path)
    except TrialLogError:
        return None
    end = log.end
    estimate = next(log.of_kind("estimate"), None)
    if not log.complete or log.bad_lines or end is None or estimate is None:
        return None
    if log.header.get("spec") != json.loads(json.dumps(spec.record())):
        return None
    try:
        outcome = _outcome(spec, stack, end, estimate, str(path))
        _restore_probe(outcome, log)
    except (KeyError, TypeError, ValueError):  # an altered log: run the trial again
        return None
    return outcome


def _outcome(
    spec: TrialSpec, stack: StackConfig, end: dict[str, Any], estimate: dict[str, Any], path: str
) -> TrialOutcome:
    marks = _marks(end["marks"])
    geo = trial_geometry(stack, spec)
    length = None
    if marks.x_buckling is not None:  # as the trial computed it: on the tube the IK picked
        length = trial_stage(spec, stack, geo).exposed_length(marks.x_buckling)
    duration = end["duration"]
    return TrialOutcome(
        spec=spec,
        state=State(end["state"]),
        reason=str(end["reason"]),
        estimate=_paper(estimate),
        exposed_length_at_buckling=length,
        ik_residual=geo.residual,
        ticks=int(end["ticks"]),
        sim_time=math.nan if duration is None else float(duration),
        log_path=path,
        marks=marks,
        joint=None if "joint" not in estimate else _joint(estimate["joint"]),
        verdict=recorded_verdict(estimate),
        southwell=_optional(SouthwellFit, estimate.get("southwell")),
        calibration=_optional(ComplianceFit, estimate.get("calibration")),
        lean=Lean.from_record(estimate["lean"]) if isinstance(estimate.get("lean"), dict) else None,
        relaxation=_relaxation(estimate.get("relaxation")),
        relaxed_verdict=recorded_verdict(estimate, "relaxed_verdict"),
        motion=_floats(estimate.get("motion"), optional=True),
        heart=_floats(estimate.get("heart"), optional=True),
    )


def _restore_probe(outcome: TrialOutcome, log: TrialLog) -> None:
    """What probing found, the misalignment the estimator was told and the world's truth."""
    told = log.header.get("estimator") or {}
    outcome.misalignment = float(told.get("misalignment", outcome.ik_residual))
    probe = next(log.of_kind("probe"), None)
    if probe is not None:
        fields = {f.name for f in dataclasses.fields(ProbeResult)}
        kwargs = {k: _floats(v, k in OPTIONAL) for k, v in probe.items() if k in fields}
        kwargs["touches"] = tuple(
            Touch(**{k: _floats(v) for k, v in t.items()}) for t in probe["touches"]
        )
        outcome.probe = ProbeResult(**kwargs)
        outcome.misalignment = outcome.probe.misalignment
        outcome.probing_time = _probing_time(log)
    world = next(log.of_kind("world"), None)
    if world is not None:
        outcome.true_misalignment = world["true_misalignment"]
        outcome.true_motion = world.get("true_motion")


OPTIONAL = frozenset({"normal", "radius"})  # ProbeResult's fields that may be None


def _floats(value: Any, optional: bool = False) -> Any:
    """JSON back to the dataclass's values: lists as tuples, null as NaN (a float written as
    null) unless the field is ``optional`` (None)."""
    if isinstance(value, list):
        return tuple(value)
    return math.nan if value is None and not optional else value


def _probing_time(log: TrialLog) -> float:
    """Seconds in the probing state, from the transitions (as ``TrialResult.probing_time``)."""
    moves = list(log.of_kind("transition"))
    start = next((t["t"] for t in moves if t["to"] == "probing"), None)
    end = next((t["t"] for t in moves if t["from"] == "probing"), None)
    return 0.0 if start is None or end is None else float(end) - float(start)


def _optional(cls: type[T], record: dict[str, Any] | None) -> T | None:
    if not isinstance(record, dict):
        return None
    names = {f.name for f in dataclasses.fields(cls)}  # type: ignore[arg-type]
    return cls(**{k: v for k, v in record.items() if k in names})


def _from_record(cls: type[T], record: dict[str, Any], sequence: str) -> T:
    """Dataclass ``cls`` from a record's fields of the same names (others ignored), the list
    field ``sequence`` as the tuple the dataclass holds."""
    names = {f.name for f in dataclasses.fields(cls)}  # type: ignore[arg-type]
    kwargs = {k: v for k, v in record.items() if k in names}
    kwargs[sequence] = tuple(kwargs.get(sequence) or ())
    return cls(**kwargs)


def _marks(record: dict[str, Any]) -> TrialMarks:
    return _from_record(TrialMarks, record, "strains_at_buckling")


def _number(value: Any) -> float:
    """A float written as null (JSON has no NaN) reads back as NaN."""
    return math.nan if value is None else float(value)


def _paper(record: dict[str, Any]) -> StiffnessEstimate | None:
    if "modulus" not in record:  # "no buckling detected": the trial had no paper estimate
        return None
    return StiffnessEstimate(
        success=bool(record["success"]),
        modulus=record["modulus"],
        delta=_number(record["delta"]),
        force=_number(record["force"]),
        message=str(record["message"]),
    )


def _joint(record: dict[str, Any]) -> JointFit:
    """The joint fit, with its share of the sample's pooled fit when the log carries it."""
    fields = {k: v for k, v in record.items() if k != "pooling"}
    fit = _from_record(JointFit, fields, "warnings")
    pooling = record.get("pooling")
    return fit if pooling is None else dataclasses.replace(fit, terms=Terms.from_dict(pooling))


def _relaxation(record: Any) -> RelaxationFit | None:
    """The relaxation fit of a trial that held (None for one that did not)."""
    return _from_record(RelaxationFit, record, "warnings") if isinstance(record, dict) else None
