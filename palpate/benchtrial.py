"""Scripted trials on the bench: stored poses -> trial plans -> the same trial loop as simulation.

:func:`plan_bench_trials` turns the bench file's trial list and the stored targets into
:class:`robot.indentation.TrialPlan` s, checked against the drive's limits before anything moves.
:func:`run_bench_trials` runs them in order on opened interfaces (:mod:`palpate.hardware`) with
:func:`robot.trial.run.run_trial` and the :class:`robot.rig.ServoFbgRig`, writes one crash-safe
log per trial as it goes (readable by ``palpate replay``) and estimates the modulus with the same
trial core (:mod:`robot.trial`) as ``palpate sim``.

A stored pose is the stand-off pose: the trial rolls there with the sensor back, advances to it,
approaches the expected surface ``standoff_mm`` further on at the approach speed, indents until
the buckling detector fires, records ``post_buckling_mm`` more and retracts.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from config.bench import BenchTrialConfig, LoadedBench
from config.loader import ConfigError
from config.schema import MM, TubeConfig
from config.targets import TargetConfig, TargetsFile, load_targets
from estimation.section import Section
from estimation.stiffness import StiffnessEstimate
from palpate.hardware import Hardware
from robot.drive import JointLimitError, JointState, RollerGearDrive
from robot.indentation import State, TrialPlan
from robot.rig import ServoFbgRig
from robot.trial.estimate import estimate_trial
from robot.trial.log import TrialLogWriter
from robot.trial.record import end_record, estimate_record, header_common
from robot.trial.run import run_trial
from robot.trial.setup import (
    detector_for,
    guards_for,
    prober_for,
    rig_settings,
    sensor_section,
    trial_plan,
)
from sensor.strain import StrainChain

SKIPPED = "skipped"


@dataclass(frozen=True)
class BenchTrial:
    """One planned trial: the pose it starts from and the plan the state machine follows."""

    trial_id: str
    kind: Literal["bench", "robot"]
    target: TargetConfig
    tube: TubeConfig
    sample: str
    modulus: float | None  # Pa, when the sample's reference modulus is known
    poisson: float
    exposed_length: float  # m at the expected contact
    plan: TrialPlan

    def describe(self) -> dict[str, Any]:
        p = self.plan
        return {
            "trial": self.trial_id,
            "target": self.target.name,
            "sample": self.sample,
            "tube": self.tube.name,
            "roll_deg": math.degrees(p.roll),
            "standoff_translation_mm": (p.contact_advance - p.standoff) / MM,
            "contact_translation_mm": p.contact_advance / MM,
            "retract_translation_mm": p.home_advance / MM,
            "exposed_length_mm": self.exposed_length / MM,
        }


@dataclass
class BenchOutcome:
    trial: BenchTrial
    state: str
    reason: str
    estimate: StiffnessEstimate | None = None
    exposed_length_at_buckling: float | None = None
    duration: float = 0.0
    log_path: str | None = None

    def as_dict(self) -> dict[str, Any]:
        est, t = self.estimate, self.trial
        modulus = None if est is None else est.modulus
        rel = None
        if modulus is not None and t.modulus is not None:
            rel = (modulus - t.modulus) / t.modulus
        return {
            **t.describe(),
            "state": self.state,
            "reason": self.reason,
            "estimated_kpa": None if modulus is None else modulus / 1e3,
            "actual_kpa": None if t.modulus is None else t.modulus / 1e3,
            "relative_error": rel,
            "delta_mm": None if est is None else est.delta / MM,
            "force_n": None if est is None else est.force,
            "duration_s": self.duration,
            "log": self.log_path,
        }


def _safe(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name).strip("_") or "trial"


def plan_bench_trials(loaded: LoadedBench, only: str | None = None) -> list[BenchTrial]:
    """The bench file's trials (each ``campaign.repeats`` times), or those at target ``only``.

    Raises ConfigError naming the file and key when a target, a tube or a limit is wrong.
    """
    bench, stack = loaded.bench, loaded.stack
    stored = load_targets(loaded.targets_path)
    drive = RollerGearDrive(stack.drive)
    trials: list[BenchTrial] = []
    for i, entry in _entries(loaded, stored, only):
        target, tube, where = _target_and_tube(loaded, stored, i, entry)
        contact = target.translation + bench.campaign.standoff_mm * MM
        home = bench.retract_translation(target.translation, drive.home.translation)
        plan = trial_plan(bench.campaign, stack, roll=target.roll, contact=contact, home=home)
        length = _exposed_length(loaded, entry, tube, contact, where)
        _check_reach(loaded, drive, target, plan, where)
        trials += _repeats(loaded, len(trials), entry, target, tube, length, plan)
    return trials


def _entries(
    loaded: LoadedBench, stored: TargetsFile, only: str | None
) -> list[tuple[int, BenchTrialConfig]]:
    """(index in ``trials``, entry) of the bench file's trials to plan; index -1 for a stored
    pose that ``only`` names and the list omits."""
    entries = list(enumerate(loaded.bench.trials))
    if only is not None:
        entries = [(i, e) for i, e in entries if e.target == only]
        if not entries:
            if not any(t.name == only for t in stored.targets):
                known = sorted(t.name for t in stored.targets)
                raise ValueError(
                    f"--target: no target named {only!r} in {loaded.targets_path}; known: {known}"
                )
            entries = [(-1, BenchTrialConfig(target=only))]  # a stored pose the list omits
    if not entries:
        raise ConfigError(str(loaded.path), "trials", "no trials listed")
    return entries


def _target_and_tube(
    loaded: LoadedBench, stored: TargetsFile, i: int, entry: BenchTrialConfig
) -> tuple[TargetConfig, TubeConfig, str]:
    """The entry's stored pose, its tube, and the pose's key in the targets file."""
    key = f"trials[{i}].target" if i >= 0 else "--target"
    try:
        target = stored.get(entry.target)
    except KeyError as exc:
        raise ConfigError(
            str(loaded.path), key, f"{exc.args[0]} in {loaded.targets_path}"
        ) from None
    where = f"targets[{[t.name for t in stored.targets].index(target.name)}]"
    try:
        tube = loaded.stack.tube(target.tube)
    except KeyError as exc:
        raise ConfigError(str(loaded.targets_path), f"{where}.tube", exc.args[0]) from None
    return target, tube, where


def _exposed_length(
    loaded: LoadedBench, entry: BenchTrialConfig, tube: TubeConfig, contact: float, where: str
) -> float:
    """The sensor's exposed length at the expected contact (m): the entry's (or the sensor's) on
    the bench stage, the advance past the tube's flush translation on the robot."""
    if loaded.bench.campaign.kind == "bench":
        return (entry.exposed_length_mm or loaded.stack.sensor.exposed_length_mm) * MM
    length = contact - tube.flush_translation
    if length <= 0:
        raise ConfigError(
            str(loaded.targets_path),
            f"{where}.translation_mm",
            f"the sensor would still be inside tube {tube.name!r} at contact "
            f"(exposed length {length / MM:.2f} mm)",
        )
    return length


def _check_reach(
    loaded: LoadedBench, drive: RollerGearDrive, target: TargetConfig, plan: TrialPlan, where: str
) -> None:
    """The farthest a trial may drive: no contact until the approach window ends, then the
    travel past contact; both must be inside the drive's limits before anything moves."""
    past = loaded.bench.campaign.max_travel_past_contact_mm * MM
    farthest = plan.contact_advance + plan.approach_window + past
    try:
        for q in (
            JointState(target.roll, plan.home_advance),
            JointState(target.roll, target.translation),
            JointState(target.roll, farthest),
        ):
            drive.check(q)
    except JointLimitError as exc:
        raise ConfigError(
            str(loaded.targets_path),
            f"{where}.translation_mm",
            f"target {target.name!r}: the trial may reach {farthest / MM:.2f} mm "
            f"(contact + approach window + travel past contact): {exc}",
        ) from None


def _repeats(
    loaded: LoadedBench,
    planned: int,
    entry: BenchTrialConfig,
    target: TargetConfig,
    tube: TubeConfig,
    length: float,
    plan: TrialPlan,
) -> list[BenchTrial]:
    """The entry's ``campaign.repeats`` trials, numbered after the ``planned`` ones."""
    c = loaded.bench.campaign
    trials: list[BenchTrial] = []
    for rep in range(c.repeats):
        parts = [f"{planned + len(trials) + 1:02d}", target.name]
        if entry.sample:
            parts.append(entry.sample)
        if c.repeats > 1:
            parts.append(f"r{rep}")
        trials.append(
            BenchTrial(
                trial_id=_safe("-".join(parts)),
                kind=c.kind,
                target=target,
                tube=tube,
                sample=entry.label,
                modulus=entry.modulus,
                poisson=entry.poisson,
                exposed_length=length,
                plan=plan,
            )
        )
    return trials


def run_bench_trials(
    hw: Hardware,
    trials: list[BenchTrial],
    loaded: LoadedBench,
    log_dir: Path,
    *,
    sync_to_clock: bool = False,
    progress: Callable[[BenchOutcome], None] | None = None,
) -> list[BenchOutcome]:
    """Run ``trials`` in order on opened hardware; one log per trial in ``log_dir``.

    ``sync_to_clock`` is for emulators on a virtual clock (wait for each tick's frame); on
    hardware it stays False. With ``stop_on_fault`` a trial that does not complete ends the
    session: the rest are reported as skipped, torque is off.
    """
    bench = loaded.bench
    outcomes: list[BenchOutcome] = []
    torque_on = True  # DriveController.start() turned it on
    stopped = False
    for trial in trials:
        if stopped:
            outcomes.append(BenchOutcome(trial, SKIPPED, "an earlier trial did not complete"))
            continue
        if not torque_on:
            hw.drive.bus.set_torque(True)
            torque_on = True
        outcome, rig = _run_one(hw, trial, loaded, log_dir, sync_to_clock)
        outcomes.append(outcome)
        if progress is not None:
            progress(outcome)
        if outcome.state != State.DONE.value:
            torque_on = False  # run_trial released the servos
            stopped = bench.stop_on_fault
        elif bench.after_trial == "release":
            rig.release()
            torque_on = False
    return outcomes


def _run_one(
    hw: Hardware, trial: BenchTrial, loaded: LoadedBench, log_dir: Path, sync_to_clock: bool
) -> tuple[BenchOutcome, ServoFbgRig]:
    """Zero the strains, run one trial with its log, estimate; the outcome and the rig."""
    stack, c = loaded.stack, loaded.bench.campaign
    tick = 1.0 / loaded.bench.control_rate_hz
    settings = rig_settings(
        c, stack, tick, sync_to_clock=sync_to_clock, exposed_length=trial.exposed_length
    )
    rig = ServoFbgRig(hw.drive, hw.reader, StrainChain.from_config(stack.fbg), hw.clock, settings)
    chain = rig.zero()
    section = sensor_section(stack)
    path = log_dir / f"{trial.trial_id}.jsonl"
    with TrialLogWriter(path, _header(trial, loaded, section)) as log:
        guards = guards_for(c, stack, rig.tick)
        # the robot probes the surface first when the campaign says so (null: it does)
        prober = prober_for(c, stack, trial.tube) if trial.kind == "robot" else None
        result = run_trial(
            rig, hw.clock, trial.plan, guards, detector_for(c, chain), log, prober=prober
        )
        estimate = estimate_trial(
            result,
            kind=trial.kind,
            exposed_length=trial.exposed_length,
            flush_translation=trial.tube.flush_translation,
            stack=stack,
            section=section,
            poisson=trial.poisson,
        )
        log.write(estimate_record(estimate))
        log.write(end_record(result))
    outcome = BenchOutcome(
        trial,
        result.state.value,
        result.reason,
        estimate.paper,
        estimate.exposed_length_at_buckling,
        result.duration,
        str(path),
    )
    return outcome, rig


def _header(trial: BenchTrial, loaded: LoadedBench, section: Section) -> dict[str, Any]:
    """The log header; the keys ``palpate replay`` reads are those of a simulated trial."""
    stack = loaded.stack
    tube = trial.tube if trial.kind == "robot" else None
    return {
        "trial": trial.trial_id,
        "source": "bench",
        "bench_file": str(loaded.path),
        "ports": {"servos": stack.servos.port, "board": stack.board.port},
        "spec": {
            "kind": trial.kind,
            "sample": trial.sample,
            "modulus": trial.modulus,
            "poisson": trial.poisson,
            "tube": trial.tube.name,
            "target": dataclasses.asdict(trial.target),
            "roll": trial.plan.roll,
            "exposed_length": trial.exposed_length,
        },
        **header_common(trial.plan, section, stack.sensor, tube, trial.poisson),
    }
