"""Replay a trial log: re-run the estimation on what it recorded and say whether it reproduces
the trial's estimates exactly (``palpate replay``, and the fault campaign's data-kept check).

Both estimates are re-run: the paper's from the marks, and the joint fit (with its verdict and
the beam's bow, or the compliance on a rigid reference) from the samples with the inputs the
header records (``estimation.trial.inputs``). A log written by an older estimator (inputs version
1, or no inputs at all) replays with what it has: the joint fit is re-run with its point
values and shown, the report says so (``note``), and only the paper's estimate is compared.
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from palpate.config.loader import from_mapping
from palpate.config.schema import SensorConfig, StackConfig, TubeConfig
from palpate.estimation.beam.section import Section
from palpate.estimation.trial.estimate import (
    EstimatorInputs,
    estimate_from_marks,
    exposed_length_at,
    fit_rows,
    tip_load_at_buckling,
    verdict_for,
)
from palpate.estimation.trial.inputs import VERSION, probe_inputs
from palpate.robot.records.log import TrialLog, TrialLogError, read_log
from palpate.robot.records.logschema import logged_number
from palpate.robot.trial.record import estimator_keys

MAX_PROBLEMS = 5  # bad lines named in the message (all are counted)


def replay(path: Path) -> dict[str, Any]:
    """Recompute the estimates from a log and compare them with the recorded ones.

    Raises TrialLogError (a ValueError) when the file is not a trial log or its header is
    wrong. A log with bad lines (beyond a last line cut short by a crash) is reported as
    ``damaged`` with the lines and what is wrong with them, and not replayed; a log without its
    end record as truncated."""
    log = read_log(path)
    h = log.header
    report: dict[str, Any] = {
        "log": str(path),
        "trial": h.get("trial"),
        "complete": log.complete,
        "bad_lines": log.bad_lines,
        "records": len(log.records),
        "problems": log.problems[:MAX_PROBLEMS],
    }
    if log.damaged:
        report["damaged"] = True
        more = len(log.damaged) - MAX_PROBLEMS
        report["message"] = (
            f"damaged log: {len(log.damaged)} bad line(s): "
            + "; ".join(log.damaged[:MAX_PROBLEMS])
            + (f"; and {more} more" if more > 0 else "")
        )
        return report
    end = log.end
    if end is None:
        transitions = list(log.of_kind("transition"))
        last = transitions[-1]["to"] if transitions else "none"
        report["message"] = (
            f"truncated log: no end record ({len(log.records)} records kept, last state {last}); "
            "no estimate can be reproduced"
        )
        return report
    try:
        _replay_complete(log, end, report)
    except (ArithmeticError, np.linalg.LinAlgError) as exc:  # well-formed, physically absurd
        raise TrialLogError(f"{path}: values out of the estimators' range ({exc})") from None
    return report


def _replay_complete(log: TrialLog, end: dict[str, Any], report: dict[str, Any]) -> None:
    """Both estimates from a complete, well-formed log, compared with the recorded ones."""
    h, path = log.header, log.path
    sensor = from_mapping(SensorConfig, _tuples(h["sensor"]), str(path), "sensor")
    section = Section(**{f.name: h["section"][f.name] for f in dataclasses.fields(Section)})
    spec = h["spec"]
    marks = end["marks"]
    x_b = marks.get("x_buckling")
    length: float | None = None
    if x_b is not None:
        flush = 0.0
        if spec["kind"] == "robot":
            flush = from_mapping(TubeConfig, h["tube"], str(path), "tube").flush_translation
        length = exposed_length_at(spec["kind"], x_b, spec["exposed_length"], flush)
        if not length > 0:
            raise TrialLogError(f"{path}: end.marks.x_buckling: exposed length {length} m <= 0")
    stack = StackConfig(sensor=sensor)
    est = estimate_from_marks(
        marks.get("x_contact"),
        x_b,
        tuple(marks.get("strains_at_buckling") or ()),
        length,
        stack,
        section,
        h["poisson"],
    )
    recorded = next(log.of_kind("estimate"), None)
    modulus = None if est is None else est.modulus
    rec = None if recorded is None else recorded.get("modulus")
    report.update(
        {
            "state": end["state"],
            "reason": end["reason"],
            "paper_modulus": modulus,  # the paper's single point (Eqs. 13-14), Pa
            "recorded_paper_modulus": rec,
            "paper_kpa": _kpa(modulus),
            "recorded_paper_kpa": _kpa(rec),
            **{f"{k}_kpa": _kpa(v) for k, v in known_moduli(h).items()},
        }
    )
    paper_same = (modulus is None and rec is None) or (
        modulus is not None and rec is not None and math.isclose(modulus, rec, rel_tol=0, abs_tol=0)
    )
    report["identical"] = paper_same and _replay_joint(log, stack, section, report)


def _replay_joint(
    log: TrialLog, stack: StackConfig, section: Section, report: dict[str, Any]
) -> bool:
    """Re-run the joint fit (its verdict and the bow, or the calibration) on the log's samples;
    True if it equals the recorded one exactly (every field, compared as JSON values), or if
    the log's estimator is older than this one (then it is shown, not compared)."""
    recorded = next(log.of_kind("estimate"), None)
    raw = log.header.get("estimator")
    if recorded is None or raw is None:
        report["joint"] = None
        report["note"] = "the log has no joint-fit inputs (written before the joint fit)"
        return True
    probe = next(log.of_kind("probe"), None)
    if probe is not None:  # the estimator was told the misalignment probing measured
        raw = {**raw, **probe_inputs(probe)}
    inputs = EstimatorInputs.from_dict(raw)
    samples = list(log.of_kind("sample"))
    rows = [(r["state"], logged_number(r["advance"]), r["strains"]) for r in samples]
    tips = [r.get("tip_force") for r in samples] if any("tip_force" in r for r in samples) else None
    beats = [r["t"] for r in samples if r.get("beat")]
    fitted = fit_rows(rows, inputs, stack, section, [r["t"] for r in samples], tips, beats)
    end = log.end or {}
    verdict, relaxed = None, None
    if not inputs.rigid:
        verdict, relaxed = verdict_for(
            fitted,
            inputs,
            str(end.get("state")),
            str(end.get("reason")),
            section,
            tip_load_at_buckling(rows, tips),
        )
    lean = fitted.lean if "lean" in recorded else None  # logs before issue 25 have none
    keys = estimator_keys(
        fitted.joint,
        verdict,
        fitted.southwell,
        fitted.calibration,
        lean,
        fitted.relaxation,
        relaxed,
    )
    replayed = json.loads(json.dumps(keys))
    report.update({f"replayed_{k}" if k != "joint" else k: v for k, v in replayed.items()})
    report["recorded_joint"] = recorded.get("joint")
    report.update({**_joint_kpa(replayed.get("joint"), ""), **_joint_kpa(recorded, "recorded_")})
    report["recorded_verdict"] = recorded.get("verdict")
    if inputs.version < VERSION:
        report["note"] = (
            f"the log's estimator inputs are version {inputs.version} (this replay: {VERSION}): "
            "re-run with the point values it records (no belief ranges, a rigid rig, no verdict "
            "limits); the joint fit is shown, not compared"
        )
        return True
    same = all(replayed[k] == recorded.get(k) for k in replayed)
    report["joint_reproduced"] = same
    return same


def known_moduli(header: dict[str, Any]) -> dict[str, float | None]:
    """The moduli (Pa) a log's header knows besides the estimates: ``truth`` (the world's, a
    simulated trial only) and ``reference`` (the sample's stated modulus: the scene's reported
    reference in simulation, the bench file's modulus on the bench); None where unknown."""
    spec = header.get("spec") or {}
    if header.get("source") == "simulation":
        return {"truth": spec.get("modulus"), "reference": spec.get("reference")}
    return {"truth": None, "reference": spec.get("modulus")}


def _tuples(d: dict[str, Any]) -> dict[str, Any]:
    return {k: tuple(v) if isinstance(v, list) else v for k, v in d.items()}


def _kpa(value: object) -> float | None:
    return float(value) / 1e3 if isinstance(value, int | float) else None


def _joint_kpa(joint: object, prefix: str) -> dict[str, Any]:
    """``joint_kpa`` and ``joint_ci_kpa`` (with ``prefix``) of a joint fit's record (or of an
    estimate record's ``joint``, with ``recorded_``)."""
    j: dict[str, Any] = joint if isinstance(joint, dict) else {}
    if prefix == "recorded_":
        inner = j.get("joint")
        j = inner if isinstance(inner, dict) else {}
    lo, hi = _kpa(j.get("ci_low")), _kpa(j.get("ci_high"))
    return {
        f"{prefix}joint_kpa": _kpa(j.get("modulus")),
        f"{prefix}joint_ci_kpa": None if lo is None or hi is None else [lo, hi],
    }
