"""Scripted trials on the bench, planned: the bench file's trial list and the stored targets as
:class:`BenchTrial` s (pose and :class:`robot.indentation.TrialPlan`), checked against the
drive's limits before anything moves (:func:`plan_bench_trials`). ``palpate.lab.trial`` runs
them.

A stored pose is the stand-off pose: the trial rolls there with the sensor back, advances to it,
approaches the expected surface ``standoff_mm`` further on at the approach speed, indents until
the buckling detector fires, records ``post_buckling_mm`` more and retracts.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any, Literal

from palpate.config.bench import BenchTrialConfig, LoadedBench
from palpate.config.loader import ConfigError, InputError
from palpate.config.sample import AssumedConfig
from palpate.config.schema import MM, TubeConfig
from palpate.config.targets import TargetConfig, TargetsFile, load_targets
from palpate.estimation.beam.stage import Stage
from palpate.robot.drive import JointLimitError, JointState, RollerGearDrive
from palpate.robot.indentation import TrialPlan
from palpate.robot.trial.setup import trial_plan


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
    assumed: AssumedConfig | None = None  # the operator's belief about the sample
    rigid: bool = False  # a rigid reference: the trial calibrates the compliance

    @property
    def stage(self) -> Stage:
        """The stage this trial advances on: the bench column or its tube."""
        return Stage.of_tube(self.kind, self.tube, self.exposed_length)

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
                raise InputError(
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
    if not loaded.bench.campaign.on_tubes:
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
                kind="robot" if c.on_tubes else "bench",
                target=target,
                tube=tube,
                sample=entry.label,
                modulus=entry.modulus,
                poisson=entry.poisson,
                exposed_length=length,
                plan=plan,
                assumed=entry.assumed,
                rigid=entry.rigid,
            )
        )
    return trials


def plan_bench_map(loaded: LoadedBench) -> BenchTrial:
    """The trial every probe of the bench file's map repeats: the first ``trials`` entry at
    ``map.target`` (checked against the drive's limits like any trial)."""
    m = loaded.bench.map
    if m is None:
        raise ValueError(f"{loaded.path} has no map: section")
    return plan_bench_trials(loaded, m.target)[0]


def plan_session(
    loaded: LoadedBench, target: str | None
) -> tuple[list[BenchTrial], BenchTrial | None]:
    """The trials to run and, when the bench file maps (and ``--target`` is not another
    pose), the trial each probe repeats: the listed trials at other targets run first."""
    m = loaded.bench.map
    if m is None or (target is not None and target != m.target):
        return plan_bench_trials(loaded, target), None
    others = target is None and any(e.target != m.target for e in loaded.bench.trials)
    trials = [t for t in plan_bench_trials(loaded) if t.target.name != m.target] if others else []
    return trials, plan_bench_map(loaded)


def describe_map(loaded: LoadedBench, survey: BenchTrial | None) -> str:
    """ "a map at ... of the x-y stage" for the session's lines; empty without a map."""
    m = loaded.bench.map
    if survey is None or m is None:
        return ""
    x0, y0, x1, y1 = m.patch_mm
    return (
        f"a map at {m.target} ({m.strategy}, at most {m.max_probes} probes over "
        f"x {x0:+g}..{x1:+g}, y {y0:+g}..{y1:+g} mm of the x-y stage)"
    )
