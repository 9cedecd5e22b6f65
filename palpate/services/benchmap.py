"""A stiffness map on the bench: the x-y stage carries the sample under the tip, each probe a
whole trial of the bench file's ``map.target`` entry (issue 40; docs/maps.md).

Between probes the drive is back at the trial's retract pose (every planned trial ends there)
and the stage moves the next point under the tip (:class:`robot.xystage.StageController`: it
refuses to move while the sensor is out, and holds where it is if the sensor leaves the retract
pose during the move). The plan, the probes file, the live view and the map are the
simulator's (``palpate.campaigns.surveyloop``), so a bench map and a simulated one read the
same. A trial that faults, or a stage that does not arrive, ends the survey with the probes so
far (the fault's probe recorded)::

    template = plan_bench_map(loaded)            # palpate.lab.plan
    result = run_bench_map(hw, template, loaded, session.stack, log_dir)
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from pathlib import Path

from palpate.campaigns.surveyloop import (
    MM,
    Point,
    SurveyPlan,
    SurveyResult,
    SurveyStopped,
    probe_name,
    run_plan,
)
from palpate.config.bench import LoadedBench
from palpate.config.schema import StackConfig
from palpate.lab.hardware import Hardware
from palpate.lab.plan import BenchTrial
from palpate.lab.trial import PLANNED, BenchOutcome, run_bench_trial
from palpate.live import View
from palpate.maps import Probe
from palpate.robot.trial.outcome import probe_of
from palpate.robot.xystage import Gantry, StageMoveError

CLEAR_MARGIN = 0.5 * MM  # the sensor counts as back within this of the retract pose


def probe_trial(template: BenchTrial, k: int, point: Point) -> BenchTrial:
    """The k-th probe's trial (1-based) at ``point`` (m): the template renamed."""
    return dataclasses.replace(template, trial_id=probe_name(k, point))


def run_bench_map(
    hw: Hardware,
    template: BenchTrial,
    loaded: LoadedBench,
    stack: StackConfig,
    log_dir: Path,
    *,
    sync_to_clock: bool = False,
    progress: Callable[[BenchOutcome], None] | None = None,
    live: View | None = None,
) -> SurveyResult:
    """Survey the bench file's ``map:`` patch on opened hardware with ``stack`` (the session's
    calibration); the trial logs and ``probes.jsonl`` in ``log_dir``. The lab time is the
    clock's: the stage's moves and the trials."""
    m = loaded.bench.map
    if m is None or hw.stage is None:
        raise ValueError("a bench map needs the bench file's map: and the robot's stage:")
    stage = hw.stage
    plan = SurveyPlan.of(
        m.patch_mm,
        m.strategy,
        m.max_probes,
        threshold=m.threshold,
        seed=m.seed,
        tip_radius=stack.sensor.tip_radius,
    )
    tick = 1.0 / loaded.bench.control_rate_hz
    back = template.plan.home_advance + CLEAR_MARGIN

    def clear() -> bool:
        return hw.drive.read()[0].translation <= back

    def probe_at(probes: list[Probe], point: Point) -> tuple[Probe, BenchOutcome | None]:
        t0 = hw.clock.now()
        try:
            stage.move_to(point, hw.clock, tick=tick, clear=clear, idle=hw.reader.poll)
        except StageMoveError as exc:
            lost = Probe(point[0], point[1], None, None, "none", (str(exc),), 0.0)
            raise SurveyStopped(lost, None, str(exc)) from exc
        trial = probe_trial(template, len(probes) + 1, point)
        outcome, _ = run_bench_trial(
            hw, trial, loaded, stack, log_dir, sync_to_clock=sync_to_clock, live=live
        )
        probe = probe_of(outcome, point, hw.clock.now() - t0, stack.sensor.tip_radius)
        if progress is not None:
            progress(outcome)
        if outcome.state not in PLANNED:
            raise SurveyStopped(probe, outcome, f"{outcome.state}: {outcome.reason}")
        return probe, outcome

    result = run_plan(plan, probe_at, run_dir=log_dir, live=live)
    result.reach = Gantry.of(stage.axes.cfg)
    return result
