"""The records of a trial log that are written once: the header's common part, the estimate and
the end (the per-tick ``sample`` and ``transition`` records are :mod:`robot.trial.run`'s).

The simulator and the bench write the same keys here, so ``palpate replay`` reads either log
the same way (see :mod:`robot.records.log` for the file format). Every key the estimator adds is
written here, and read back here (:func:`recorded_verdict`), tolerant of logs that predate it:

- header ``estimator``: the joint fit's inputs (``estimation.trial.inputs.EstimatorInputs``, with
  ``version``; version 2 added the belief's ranges, the compliance and the verdict's limits);
- estimate ``joint``: the joint fit (``JointFit.as_dict``); ``verdict``: ``{status, reasons}``
  (ok, suspect or none); ``southwell``: the beam's bow fitted from the record. A log without
  ``verdict`` was written before verdicts existed. On a rigid reference (``estimator.rigid``)
  the estimate record carries ``calibration`` (``ComplianceFit.as_dict``, m/N) instead. A trial
  that held adds ``relaxation`` (``RelaxationFit.as_dict``) and ``relaxed_verdict``.
"""

from __future__ import annotations

from dataclasses import asdict
from typing import TYPE_CHECKING, Any, Protocol

from ...config.schema import SensorConfig, TubeConfig
from ...estimation.beam.section import Section
from ...estimation.fits.compliance import ComplianceFit
from ...estimation.fits.southwell import SouthwellFit
from ...estimation.fits.stiffness import StiffnessEstimate
from ...estimation.jointfit import JointFit
from ...estimation.pose.misalignment import Lean
from ...estimation.relaxation import RelaxationFit
from ...estimation.verdict import Verdict
from ..indentation import TrialPlan

if TYPE_CHECKING:  # types only: estimate.py is above this module
    from ...estimation.trial.estimate import TrialEstimate
    from ...estimation.trial.inputs import EstimatorInputs

UNITS = "SI (m, N, Pa, rad, s); strains dimensionless"


def header_common(
    plan: TrialPlan,
    section: Section,
    sensor: SensorConfig,
    tube: TubeConfig | None,
    poisson: float,
    estimator: EstimatorInputs | None = None,
) -> dict[str, Any]:
    """The header keys every trial log has, after the runner's own (trial, source, spec, ...):
    what ``palpate replay`` needs to re-run the estimates. ``tube`` None on the bench stage;
    ``estimator`` the joint fit's inputs, when the runner fits one."""
    header: dict[str, Any] = {
        "plan": asdict(plan),
        "section": asdict(section),
        "sensor": asdict(sensor),
        "tube": None if tube is None else asdict(tube),
        "poisson": poisson,
    }
    if estimator is not None:
        header["estimator"] = estimator.as_dict()
    header["units"] = UNITS
    return header


def joint_record(fit: JointFit | None) -> dict[str, Any]:
    """The joint fit as it goes into the log's estimate record and ``--json``."""
    if fit is None:
        return {"success": False, "message": "no loading record"}
    if fit.terms is None:
        return fit.as_dict()
    return {**fit.as_dict(), "pooling": fit.terms.as_dict()}  # its share of a per-sample fit


def estimate_record(estimate: TrialEstimate) -> dict[str, Any]:
    """The ``estimate`` record: the paper's estimate, the joint fit, its verdict and the bow."""
    est = estimate.paper
    if est is None:
        record: dict[str, Any] = {
            "kind": "estimate",
            "success": False,
            "message": "no buckling detected",
        }
    else:
        record = {
            "kind": "estimate",
            "success": est.success,
            "modulus": est.modulus,
            "delta": est.delta,
            "force": est.force,
            "exposed_length": estimate.exposed_length_at_buckling,
            "message": est.message,
        }
    record.update(
        estimator_keys(
            estimate.joint,
            estimate.verdict,
            estimate.southwell,
            estimate.calibration,
            estimate.lean,
            estimate.relaxation,
            estimate.relaxed_verdict,
        )
    )
    # the surface's motion and the heart's beat (m), where the record held them: a resumed
    # campaign's row reads them back
    record.update(
        {k: v for k, v in (("motion", estimate.motion), ("heart", estimate.heart)) if v is not None}
    )
    return record


def estimator_keys(
    joint: JointFit | None,
    verdict: Verdict | None,
    southwell: SouthwellFit | None,
    calibration: ComplianceFit | None = None,
    lean: Lean | None = None,
    relaxation: RelaxationFit | None = None,
    relaxed: Verdict | None = None,
) -> dict[str, Any]:
    """The estimate record's keys of the joint fit, its verdict and the bow, or of the
    compliance calibration on a rigid reference (as JSON values); ``palpate replay`` compares
    its re-run with these."""
    if calibration is not None:
        return {"calibration": calibration.as_dict()}
    out: dict[str, Any] = {"joint": joint_record(joint)}
    if verdict is not None:
        out["verdict"] = verdict.as_dict()
    if southwell is not None:
        out["southwell"] = southwell.as_dict()
    if lean is not None:
        out["lean"] = lean.record()
    if relaxation is not None:
        out["relaxation"] = relaxation.as_dict()
        if relaxed is not None:
            out["relaxed_verdict"] = relaxed.as_dict()
    return out


class Estimated(Protocol):
    """A finished trial's estimates, as both outcome types hold them (the simulator's
    ``TrialOutcome``, the bench's ``BenchOutcome``)."""

    estimate: StiffnessEstimate | None  # the paper's single point (Eqs. 13-14)
    joint: JointFit | None
    verdict: Verdict | None
    calibration: ComplianceFit | None
    relaxation: RelaxationFit | None
    relaxed_verdict: Verdict | None
    motion: float | None
    heart: float | None


def estimate_row(o: Estimated) -> dict[str, Any]:
    """A trial row's estimate keys (``--json`` of ``palpate sim`` and ``palpate trial``, the
    run folder's ``trials.csv``): the joint fit's number and interval (none where its verdict
    is ``none``), the verdict (none on a rigid reference: a calibration), the paper's single
    point beside it, the calibration and a hold's relaxed modulus; moduli in kPa."""
    status = "none" if o.verdict is None else o.verdict.status
    shown = o.joint if status != "none" else None
    est = o.estimate
    return {
        "joint_kpa": None if shown is None else _kpa(shown.modulus),
        "joint_ci_kpa": None if shown is None else [_kpa(shown.ci_low), _kpa(shown.ci_high)],
        "verdict": status if o.calibration is None else None,
        "verdict_reasons": [] if o.verdict is None else list(o.verdict.reasons),
        "paper_kpa": None if est is None else _kpa(est.modulus),
        "paper_delta_mm": None if est is None else est.delta * 1e3,
        "paper_force_n": None if est is None else est.force,
        "calibration": None if o.calibration is None else o.calibration.as_dict(),
        **relaxed_row(o.relaxation, o.relaxed_verdict),
        **({} if o.motion is None else {"motion_mm": o.motion * 1e3}),
        **({} if o.heart is None else {"heart_mm": o.heart * 1e3}),
    }


def _kpa(v: float | None) -> float | None:
    return None if v is None else v / 1e3


def relaxed_row(fit: RelaxationFit | None, verdict: Verdict | None) -> dict[str, Any]:
    """A trial's row keys (``--json`` of ``palpate sim`` and ``palpate trial``) of its
    relaxation fit, moduli in kPa; empty for a trial that did not hold."""
    if fit is None:
        return {}

    return {
        "relaxed_kpa": _kpa(fit.relaxed),
        "relaxed_ci_kpa": [_kpa(fit.relaxed_low), _kpa(fit.relaxed_high)],
        "instantaneous_kpa": _kpa(fit.instantaneous),
        "relaxation_time_s": fit.relaxation_time,
        "relaxes": fit.relaxes,
        "relaxation_complete": fit.complete,
        "relaxation_delta_chi2": fit.delta_chi2,
        "relaxed_verdict": None if verdict is None else verdict.status,
        "relaxed_reasons": [] if verdict is None else list(verdict.reasons),
    }


def recorded_verdict(record: dict[str, Any] | None, key: str = "verdict") -> Verdict | None:
    """The verdict (or ``relaxed_verdict``) of a log's estimate record; None for a log written
    before verdicts (or without a hold)."""
    if record is None or not isinstance(record.get(key), dict):
        return None
    return Verdict.from_dict(record[key])
