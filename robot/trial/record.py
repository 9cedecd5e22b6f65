"""The records of a trial log that are written once: the header's common part, the estimate and
the end (the per-tick ``sample`` and ``transition`` records are :mod:`robot.trial.run`'s).

The simulator and the bench write the same keys here, so ``palpate replay`` reads either log
the same way (see :mod:`robot.trial.log` for the file format).
"""

from __future__ import annotations

import math
from dataclasses import asdict
from typing import TYPE_CHECKING, Any

from config.schema import SensorConfig, TubeConfig
from estimation.jointfit import JointFit
from estimation.section import Section
from robot.indentation import TrialPlan

if TYPE_CHECKING:  # types only: run.py and estimate.py import this module
    from robot.trial.estimate import EstimatorInputs, TrialEstimate
    from robot.trial.run import TrialResult

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
    return fit.as_dict()


def estimate_record(estimate: TrialEstimate) -> dict[str, Any]:
    """The ``estimate`` record: the paper's estimate and the joint fit."""
    est, joint = estimate.paper, estimate.joint
    if est is None:
        return {
            "kind": "estimate",
            "success": False,
            "message": "no buckling detected",
            "joint": joint_record(joint),
        }
    return {
        "kind": "estimate",
        "success": est.success,
        "modulus": est.modulus,
        "delta": est.delta,
        "force": est.force,
        "exposed_length": estimate.exposed_length_at_buckling,
        "message": est.message,
        "joint": joint_record(joint),
    }


def end_record(result: TrialResult) -> dict[str, Any]:
    """The closing record of a trial log: final state, reason, marks, ticks and duration."""
    marks = asdict(result.marks)
    marks["strains_at_buckling"] = list(result.marks.strains_at_buckling)
    return {
        "kind": "end",
        "state": result.state.value,
        "reason": result.marks.reason,
        "marks": marks,
        "ticks": result.ticks,
        "duration": result.duration if math.isfinite(result.duration) else None,
    }
