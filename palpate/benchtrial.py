"""Scripted trials on the bench: stored poses -> trial plans -> the same trial loop as simulation.

:func:`plan_bench_trials` turns the bench file's trial list and the stored targets into
:class:`robot.indentation.TrialPlan` s, checked against the drive's limits before anything moves.
:func:`run_bench_trials` runs them in order on opened interfaces (:mod:`palpate.hardware`) with
:func:`robot.trial.run_trial` and the :class:`robot.rig.ServoFbgRig`, writes one crash-safe log
per trial as it goes (readable by ``palpate replay``) and estimates the modulus with the same
functions as ``palpate sim``.

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
from config.schema import MM, StackConfig, TubeConfig
from config.targets import TargetConfig, load_targets
from estimation.section import Section
from estimation.stiffness import StiffnessEstimate
from palpate.hardware import Hardware
from palpate.simtrial import estimate_from_marks, estimate_record, exposed_length_at
from palpate.trialsetup import (
    detector_for,
    guards_for,
    position_tolerance,
    rig_settings,
    sensor_section,
)
from robot.drive import JointLimitError, JointState, RollerGearDrive
from robot.indentation import State, TrialMarks, TrialPlan
from robot.rig import ServoFbgRig
from robot.trial import end_record, run_trial
from robot.triallog import TrialLogWriter
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
    c = bench.campaign
    stored = load_targets(loaded.targets_path)
    entries = list(enumerate(bench.trials))
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
    drive = RollerGearDrive(stack.drive)
    trials: list[BenchTrial] = []
    for i, entry in entries:
        key = f"trials[{i}].target" if i >= 0 else "--target"
        try:
            target = stored.get(entry.target)
        except KeyError as exc:
            raise ConfigError(
                str(loaded.path), key, f"{exc.args[0]} in {loaded.targets_path}"
            ) from None
        where = f"targets[{[t.name for t in stored.targets].index(target.name)}]"
        try:
            tube = stack.tube(target.tube)
        except KeyError as exc:
            raise ConfigError(str(loaded.targets_path), f"{where}.tube", exc.args[0]) from None
        standoff = c.standoff_mm * MM
        contact = target.translation + standoff
        home = bench.retract_translation(target.translation, drive.home.translation)
        plan = TrialPlan(
            roll=target.roll,
            contact_advance=contact,
            home_advance=home,
            standoff=standoff,
            post_buckling_travel=c.post_buckling_mm * MM,
            fast_speed=stack.drive.max_speed,
            approach_speed=c.approach_speed_mm_per_s * MM,
            indent_speed=c.indent_speed_mm_per_s * MM,
            position_tolerance=position_tolerance(stack),
        )
        if c.kind == "bench":
            length = (entry.exposed_length_mm or stack.sensor.exposed_length_mm) * MM
        else:
            length = contact - tube.flush_translation
            if length <= 0:
                raise ConfigError(
                    str(loaded.targets_path),
                    f"{where}.translation_mm",
                    f"the sensor would still be inside tube {tube.name!r} at contact "
                    f"(exposed length {length / MM:.2f} mm)",
                )
        # The farthest a trial may drive: no contact until the approach window ends, then the
        # travel past contact; both must be inside the drive's limits before anything moves.
        farthest = contact + plan.approach_window + c.max_travel_past_contact_mm * MM
        try:
            for q in (
                JointState(target.roll, home),
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
        for rep in range(c.repeats):
            parts = [f"{len(trials) + 1:02d}", target.name]
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
    bench, stack = loaded.bench, loaded.stack
    c = bench.campaign
    tick = 1.0 / bench.control_rate_hz
    guards = guards_for(c, stack, tick)
    section = sensor_section(stack)
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
        settings = rig_settings(
            c, stack, tick, sync_to_clock=sync_to_clock, exposed_length=trial.exposed_length
        )
        rig = ServoFbgRig(
            hw.drive, hw.reader, StrainChain.from_config(stack.fbg), hw.clock, settings
        )
        chain = rig.zero()
        path = log_dir / f"{trial.trial_id}.jsonl"
        with TrialLogWriter(path, _header(trial, loaded, section)) as log:
            result = run_trial(rig, hw.clock, trial.plan, guards, detector_for(c, chain), log)
            estimate, length = _estimate(trial, result.marks, stack, section)
            log.write(estimate_record(estimate, length))
            log.write(end_record(result))
        outcome = BenchOutcome(
            trial,
            result.state.value,
            result.reason,
            estimate,
            length,
            result.duration,
            str(path),
        )
        outcomes.append(outcome)
        if progress is not None:
            progress(outcome)
        if result.state is not State.DONE:
            torque_on = False  # run_trial released the servos
            stopped = bench.stop_on_fault
        elif bench.after_trial == "release":
            rig.release()
            torque_on = False
    return outcomes


def _estimate(
    trial: BenchTrial, marks: TrialMarks, stack: StackConfig, section: Section
) -> tuple[StiffnessEstimate | None, float | None]:
    if marks.x_buckling is None:
        return None, None
    length = exposed_length_at(
        trial.kind, marks.x_buckling, trial.exposed_length, trial.tube.flush_translation
    )
    est = estimate_from_marks(
        marks.x_contact,
        marks.x_buckling,
        marks.strains_at_buckling,
        length,
        stack,
        section,
        trial.poisson,
    )
    return est, length


def _header(trial: BenchTrial, loaded: LoadedBench, section: Section) -> dict[str, Any]:
    """The log header; the keys ``palpate replay`` reads are those of a simulated trial."""
    stack = loaded.stack
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
        "plan": dataclasses.asdict(trial.plan),
        "section": dataclasses.asdict(section),
        "sensor": dataclasses.asdict(stack.sensor),
        "tube": dataclasses.asdict(trial.tube) if trial.kind == "robot" else None,
        "poisson": trial.poisson,
        "units": "SI (m, N, Pa, rad, s); strains dimensionless",
    }
