"""Running the fault campaign: its jobs, one trial under a fault (in a child process that is
SIGKILLed for the killed case), the campaign over a process pool, its table, and
``palpate sim --faults`` (:func:`run_command`).

Each job is one of the scene's campaign trials under one fault case; the injector
(:mod:`palpate.faults.injector`) fires the fault and records the ground truth, the judge
(:mod:`palpate.faults.judge`) decides whether the trial stopped safely and kept its data.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import math
import os
import pickle
import signal
import subprocess
import sys
import tempfile
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from palpate.campaigns.campaign import campaign_trials
from palpate.campaigns.executors import process_pool
from palpate.campaigns.runs import locked, new_run_dir
from palpate.config.faults import FaultCase
from palpate.config.loader import ConfigError, from_mapping
from palpate.config.scene import SceneConfig
from palpate.config.schema import StackConfig
from palpate.faults.injector import FaultInjector, GroundTruth
from palpate.faults.judge import FaultJob, FaultTrialResult, judge, judge_killed
from palpate.sim.board import BoardFaults
from palpate.simulation.preflight import check_campaign, check_reachable
from palpate.simulation.trial import TrialOutcome, run_sim_trial

log = logging.getLogger(__name__)


def board_faults_of(case: FaultCase, source: str, index: int) -> BoardFaults | None:
    """The case's board faults, validated; a bad key raises ConfigError naming file and key."""
    if case.board is None:
        return None
    return from_mapping(BoardFaults, case.board, source, f"faults.cases[{index}].board")


def check_fault_scene(scene: SceneConfig, source: str) -> None:
    """Validate what the scene loader cannot (board fault keys live in ``sim``)."""
    if not scene.faults.cases:
        raise ConfigError(source, "faults.cases", "a fault campaign needs at least one case")
    for i, case in enumerate(scene.faults.cases):
        board_faults_of(case, source, i)


def _scene_for(case: FaultCase, scene: SceneConfig) -> SceneConfig:
    if case.tube_tip_stiffness_n_per_mm is None:
        return scene
    fid = dataclasses.replace(
        scene.fidelity, tube_tip_stiffness_n_per_mm=case.tube_tip_stiffness_n_per_mm
    )
    return dataclasses.replace(scene, fidelity=fid)


def _injector(job: FaultJob, **kwargs: Any) -> FaultInjector:
    board = job.board
    if board is not None:
        board = dataclasses.replace(board, seed=board.seed + job.spec.seed)
    return FaultInjector(
        job.case, job.stack.servos, seed=job.spec.seed, board_faults=board, **kwargs
    )


def run_fault_trial(job: FaultJob) -> FaultTrialResult:
    """Run one trial under one fault case and judge it. Never raises for a trial's failure."""
    if job.case.kill:
        return _run_killed(job)
    inj = _injector(job)
    outcome: TrialOutcome | None = None
    crash = ""
    try:
        outcome = run_sim_trial(
            job.spec,
            _scene_for(job.case, job.scene),
            job.stack,
            transport="wire" if job.transport == "wire" else "fast",
            log_dir=job.log_dir,
            hook=inj,
        )
    except Exception as exc:  # the campaign reports it: "nothing raises" is what it checks
        crash = f"raised {type(exc).__name__}: {exc}"
    return judge(job, outcome, inj.truth, crash)


# -- the killed process ----------------------------------------------------------------------


def child_command(job: FaultJob, blackbox: Path, ready_after_records: int | None = None) -> Any:
    """argv and the pickled job file for a child that runs ``job`` (and may kill itself)."""
    fd, name = tempfile.mkstemp(prefix="palpate-fault-", suffix=".pkl")
    with os.fdopen(fd, "wb") as fh:
        pickle.dump((job, str(blackbox), ready_after_records), fh)
    return [sys.executable, "-m", "palpate.faults", name], Path(name)


def child_main(job_file: str) -> int:
    """Entry of the child process: run the job's trial; report readiness on stdout (fd 1)."""
    with open(job_file, "rb") as fh:
        job, blackbox, ready_after = pickle.load(fh)
    inj = _injector(
        job,
        blackbox=Path(blackbox),
        ready_after_records=ready_after,
        ready_fd=1 if ready_after is not None else None,
    )
    run_sim_trial(
        job.spec, _scene_for(job.case, job.scene), job.stack, log_dir=job.log_dir, hook=inj
    )
    return 0


def _run_killed(job: FaultJob) -> FaultTrialResult:
    log_path = job.log_dir / f"{job.spec.trial_id}.jsonl"
    blackbox = job.log_dir / f"{job.spec.trial_id}.blackbox.json"
    argv, job_file = child_command(job, blackbox)
    try:
        proc = subprocess.run(argv, capture_output=True, check=False, timeout=600)
    finally:
        job_file.unlink(missing_ok=True)
    truth = GroundTruth()
    problems: list[str] = []
    if proc.returncode != -signal.SIGKILL:
        err = proc.stderr.decode(errors="replace").strip().splitlines()[-1:] or [""]
        problems.append(f"child exited with {proc.returncode}, not killed: {err[0]}")
        return FaultTrialResult(
            job.case.name, job.spec.trial_id, "not killed", "", False, False, problems,
            str(log_path), truth,
        )  # fmt: skip
    return judge_killed(job, log_path, blackbox, problems)


# -- the campaign ----------------------------------------------------------------------------


def fault_jobs(
    scene: SceneConfig, stack: StackConfig, source: str, seed: int, log_dir: Path, transport: str
) -> list[FaultJob]:
    """``trials_per_case`` trials of the scene's campaign under each case (fixed order)."""
    check_fault_scene(scene, source)
    specs = campaign_trials(scene, stack, seed)
    if not specs:
        raise ValueError(f"{source}: the campaign has no trials")
    jobs = []
    n = scene.faults.trials_per_case
    for i, case in enumerate(scene.faults.cases):
        board = board_faults_of(case, source, i)
        for j in range(n):
            base = specs[j % len(specs)]
            spec = dataclasses.replace(
                base,
                trial_id=f"{case.name}-{base.trial_id}-{j}",
                seed=base.seed + 7919 * (i + 1) + j,
            )
            jobs.append(FaultJob(case, board, spec, scene, stack, log_dir, transport))
    return jobs


def run_fault_campaign(
    jobs: Sequence[FaultJob],
    *,
    workers: int = 1,
    progress: Callable[[FaultTrialResult], None] | None = None,
) -> list[FaultTrialResult]:
    """Run the jobs (in parallel with ``workers`` > 1); results keep the jobs' order."""
    results: list[FaultTrialResult] = []
    if workers <= 1:
        for job in jobs:
            results.append(run_fault_trial(job))
            if progress is not None:
                progress(results[-1])
        return results
    with process_pool(workers) as pool:
        for res in pool.map(run_fault_trial, jobs):
            results.append(res)
            if progress is not None:
                progress(res)
    return results


@dataclass(frozen=True)
class FaultRow:
    fault: str
    trials: int
    safe_stops: int
    data_kept: int
    outcome: str  # the most common final state and reason


def fault_table(results: Sequence[FaultTrialResult]) -> list[FaultRow]:
    rows: list[FaultRow] = []
    order = list(dict.fromkeys(r.case for r in results))
    for name in order:
        rs = [r for r in results if r.case == name]
        outcomes = [f"{r.state}: {r.reason}" for r in rs]
        common = Counter(outcomes).most_common(1)[0][0]  # ties: the first seen
        rows.append(
            FaultRow(
                name,
                len(rs),
                sum(r.safe for r in rs),
                sum(r.data_kept for r in rs),
                common,
            )
        )
    return rows


def run_command(args: Any) -> int:
    """``palpate sim --faults``: exit 0 when every trial stopped safely and kept its data."""
    from palpate.config import load, load_stack, resolve

    if getattr(args, "resume", False):
        raise ValueError("--resume: the fault campaign always runs anew (it judges every trial)")
    scene_path = args.scene if args.scene else resolve("scenes/faults.yaml")
    scene = load(SceneConfig, scene_path)
    stack = load_stack(resolve(scene.robot))
    robot_source = str(resolve(scene.robot))
    check_campaign(scene, stack, str(scene_path), robot_source)
    transport = "wire" if args.wire else scene.transport
    # planned and checked in a folder not yet made; then written to a new one, never shared
    jobs = fault_jobs(scene, stack, str(scene_path), args.seed, Path("logs"), transport)
    if args.limit:
        jobs = jobs[: args.limit]
    check_reachable([j.spec for j in jobs], stack, str(scene_path), robot_source)
    with locked(new_run_dir(args.out / scene.name)) as run_dir:
        log_dir = run_dir / "logs"
        log_dir.mkdir()
        jobs = [dataclasses.replace(j, log_dir=log_dir) for j in jobs]
        return _run_and_report(jobs, args, scene.name, transport, log_dir)


def _run_and_report(
    jobs: list[FaultJob], args: Any, scene_name: str, transport: str, log_dir: Path
) -> int:
    """Run the fault jobs, print the table (or ``--json``); exit 0 when every trial stopped
    safely and kept its data."""

    def progress(r: FaultTrialResult) -> None:
        mark = "ok" if r.safe and r.data_kept else "FAILED"
        log.info("  %s: %s: %s: %s", r.trial, mark, r.state, r.reason)

    results = run_fault_campaign(jobs, workers=max(1, args.workers), progress=progress)
    rows = fault_table(results)
    if args.json:
        payload = {
            "scene": scene_name,
            "log_dir": str(log_dir),
            "transport": transport,
            "seed": args.seed,
            "faults": [dataclasses.asdict(r) for r in rows],
            "trials": [r.as_dict() for r in results],
        }
        print(json.dumps(payload, indent=2, default=_json_default))
    else:
        print(render_table(rows))
        for r in results:
            if r.problems:
                print(f"  {r.trial}: {'; '.join(r.problems)}")
        print(f"logs: {log_dir}")
    ok = all(r.safe and r.data_kept for r in results)
    return 0 if ok else 1


def _json_default(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return str(value)


def render_table(rows: Sequence[FaultRow]) -> str:
    """The fault table as text: fault, trials, safe stops, data kept, most common outcome."""
    head = f"{'fault':<24} {'trials':>6} {'safe stops':>10} {'data kept':>9}  outcome"
    lines = [head, "-" * len(head)]
    for r in rows:
        outcome = r.outcome if len(r.outcome) <= 70 else r.outcome[:67] + "..."
        lines.append(f"{r.fault:<24} {r.trials:>6} {r.safe_stops:>10} {r.data_kept:>9}  {outcome}")
    return "\n".join(lines)
