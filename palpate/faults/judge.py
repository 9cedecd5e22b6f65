"""The judge of the fault campaign: did a trial stop safely and keep its data? Judged from the
emulators and the logs (the injector's :class:`~palpate.faults.injector.GroundTruth`), never
from what the controller believes.

Definitions (checked per trial by :func:`judge`):

**Safe stop** — all of:

1. the trial returned a final state (done, fault or aborted): nothing raised out of it;
2. the fiber's true strain (the world's, noise-free) never exceeded the strain limit;
3. the true advance past first touch never exceeded the travel guard plus ``TRAVEL_SLACK``;
4. at the end every servo is still (zero velocity) and either torque-free or holding within
   one encoder tick of its goal (so nothing moves on after the trial);
5. the sensor is off the tissue at the end (true advance past contact <= 0, zero force), unless
   retraction was impossible (the translation servo stalled, shut down or not answering at the
   end), in which case its torque must be off.

For a killed process (SIGKILL, nothing can run after it), 4-5 become: the translation servo's
last goal is within ``KILL_STOP_SLACK`` of where it is, so a servo left holding its goal stops
there; the emulator's state is written by the child just before it kills itself.

**Data kept** — all of: the log reads back with no bad line; it has its end record with the
same final state and reason the trial returned, and a non-empty reason; it holds one sample
record per control tick; and ``palpate replay`` reproduces the trial's estimate exactly from it.
For a killed process: every record written (flushed) before the kill reads back, there is no end
record, and replay reports the log as truncated.
"""

from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from palpate.config.faults import FaultCase
from palpate.config.scene import SceneConfig
from palpate.config.schema import StackConfig
from palpate.faults.injector import GroundTruth
from palpate.reports.replay import replay
from palpate.robot.records.log import read_log
from palpate.sim.board import BoardFaults
from palpate.simulation.trial import TrialOutcome, TrialSpec
from palpate.wire import dynamixel as tables

TRAVEL_SLACK = 0.1e-3  # m past the travel guard: a tick or two at approach speed, tracking lag
KILL_STOP_SLACK = 0.1e-3  # m a held servo may still travel toward its last goal after a kill


@dataclass
class FaultTrialResult:
    case: str
    trial: str
    state: str
    reason: str
    safe: bool
    data_kept: bool
    problems: list[str]
    log: str | None
    truth: GroundTruth

    def as_dict(self) -> dict[str, Any]:
        d = dataclasses.asdict(self)
        d["truth"] = {k: v for k, v in d["truth"].items() if k != "servos"}
        return d


@dataclass(frozen=True)
class FaultJob:
    case: FaultCase
    board: BoardFaults | None
    spec: TrialSpec
    scene: SceneConfig
    stack: StackConfig
    log_dir: Path
    transport: str = "fast"


def judge(
    job: FaultJob, outcome: TrialOutcome | None, truth: GroundTruth, crash: str = ""
) -> FaultTrialResult:
    """Apply the safe-stop and data-kept definitions of this module's docstring."""
    problems: list[str] = []
    safe = _truth_within_limits(job, truth, problems)
    if outcome is None:
        problems.append(crash or "no outcome")
        log_path = job.log_dir / f"{job.spec.trial_id}.jsonl"
        return FaultTrialResult(
            job.case.name, job.spec.trial_id, "crash", crash, False, False, problems,
            str(log_path) if log_path.exists() else None, truth,
        )  # fmt: skip
    if outcome.state not in ("done", "fault", "aborted"):
        safe = _fail(problems, f"final state {outcome.state!r}")
    for name, s in truth.servos.items():
        if s.velocity != 0.0:
            safe = _fail(problems, f"{name} still moving at {s.velocity:.0f} ticks/s")
        if s.torque and s.remaining_ticks > 1:
            safe = _fail(problems, f"{name} holds torque {s.remaining_ticks} ticks off its goal")
    touching = truth.end_past_contact > 0.0 or truth.end_force > 0.0
    if touching:
        blocked = truth.translation_blocked
        torque = truth.servos["translation"].torque if truth.servos else True
        if not blocked:
            safe = _fail(
                problems, f"not retracted: {truth.end_past_contact * 1e3:.3f} mm past contact"
            )
        elif torque:
            safe = _fail(problems, f"translation {blocked} and still torqued against the tissue")
    kept = _data_kept(outcome, problems)
    return FaultTrialResult(
        job.case.name,
        job.spec.trial_id,
        outcome.state,
        outcome.reason,
        safe,
        kept,
        problems,
        outcome.log_path,
        truth,
    )


def _fail(problems: list[str], text: str) -> bool:
    problems.append(text)
    return False


def _truth_within_limits(job: FaultJob, truth: GroundTruth, problems: list[str]) -> bool:
    ok = True
    limit = job.stack.fbg.strain_limit
    if truth.max_strain > limit:
        ok = _fail(problems, f"true strain {truth.max_strain * 1e6:.0f} ue over the limit")
    travel = job.scene.campaign.max_travel_past_contact + TRAVEL_SLACK
    if truth.max_past_contact > travel:
        ok = _fail(problems, f"true travel past contact {truth.max_past_contact * 1e3:.3f} mm")
    return ok


def _data_kept(outcome: TrialOutcome, problems: list[str]) -> bool:
    if outcome.log_path is None:
        return _fail(problems, "no log")
    path = Path(outcome.log_path)
    log = read_log(path)
    ok = True
    if log.bad_lines:
        ok = _fail(problems, f"{log.bad_lines} unreadable log lines")
    end = log.end
    if end is None:
        return _fail(problems, "log has no end record")
    if end.get("state") != outcome.state or end.get("reason") != outcome.reason:
        ok = _fail(problems, f"log ends {end.get('state')}/{end.get('reason')!r}")
    if not end.get("reason"):
        ok = _fail(problems, "log does not say why the trial ended")
    samples = sum(1 for _ in log.of_kind("sample"))
    if samples != outcome.ticks:
        ok = _fail(problems, f"{samples} sample records for {outcome.ticks} ticks")
    if not replay(path).get("identical"):
        ok = _fail(problems, "replay does not reproduce the estimate")
    return ok


def judge_killed(
    job: FaultJob, log_path: Path, blackbox: Path, problems: list[str]
) -> FaultTrialResult:
    """Safe stop and data kept for a trial whose process was SIGKILLed (module docstring)."""
    truth = GroundTruth()
    box = json.loads(blackbox.read_text(encoding="utf-8"))
    truth.fired_at = box["t"]
    truth.max_strain = box["max_strain"]
    truth.max_past_contact = box["max_past_contact"]
    truth.records_written = box["records_written"]
    safe = _truth_within_limits(job, truth, problems)
    lead = job.stack.drive.lead
    remaining = box["servos"]["translation"]["remaining_ticks"] * lead / tables.TICKS_PER_REV
    if remaining > KILL_STOP_SLACK:
        safe = _fail(problems, f"the stage would still travel {remaining * 1e3:.3f} mm")
    kept = True
    log = read_log(log_path)
    read_back = 1 + len(log.records)  # header included, as the writer counts
    if log.bad_lines:
        kept = _fail(problems, f"{log.bad_lines} unreadable log lines")
    if read_back != truth.records_written:
        kept = _fail(problems, f"{read_back} records read back, {truth.records_written} written")
    if log.complete:
        kept = _fail(problems, "a killed trial's log has an end record")
    if "truncated" not in str(replay(log_path).get("message", "")):
        kept = _fail(problems, "replay does not report the truncated log")
    return FaultTrialResult(
        job.case.name, job.spec.trial_id, "killed", "SIGKILL", safe, kept, problems,
        str(log_path), truth,
    )  # fmt: skip
