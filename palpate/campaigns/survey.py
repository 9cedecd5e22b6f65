"""A map survey in simulation: probe a patch of one sample point by point, map it, find the
inclusion (issue 40; docs/maps.md).

Each probe is a whole trial of the one session (``simulation.trial.run_sim_trial``: the servos
on the emulated bus, the board's frames, the state machine, the estimator), on the bench column
at the campaign's first exposed length, with the sample moved under the tip: the world sees the
sample's inclusion from the probe's point (``sim.sample_law.fe_world``; a map scene interpolates
the 3-D factor between solved distances, ``fidelity.inclusion_offsets: interpolated``). The plan
(``maps.sampling``) picks each next point from the probes so far; the lab time adds
each trial's simulated time and the x-y stage's travel at ``campaign.stage_speed_mm_per_s``.
Probes are appended to ``probes.jsonl`` as they finish, so a killed survey resumes where it
stopped (every plan is a function of the probes before it)::

    result = run_survey(scene, stack, seed=0, run_dir=Path("out/map/run"))
    result.summary.found, result.summary.centre, result.scores()
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from palpate.campaigns.surveyloop import (
    MM,
    PROBES_FILE,
    Point,
    SurveyPlan,
    SurveyResult,
    Truth,
    map_of,
    probe_name,
    publish_map,
    read_probes,
    run_plan,
)
from palpate.campaigns.throughrobot import ThroughRobot, measured_tilt, oblique, refused
from palpate.config.sample import SampleConfig
from palpate.config.scene import SceneConfig
from palpate.config.schema import StackConfig
from palpate.maps import Probe
from palpate.robot.plan import State
from palpate.robot.trial.outcome import probe_of
from palpate.simulation.trial import TrialOutcome, run_sim_trial
from palpate.simulation.world import BENCH_COLUMN, TrialSpec

if TYPE_CHECKING:
    from palpate.live import View

__all__ = [
    "PROBES_FILE",
    "SurveyResult",
    "Truth",
    "map_of",
    "moved_scene",
    "probe_spec",
    "publish_map",
    "read_probes",
    "run_survey",
    "truth_of",
]


def truth_of(sample: SampleConfig) -> Truth | None:
    if not sample.inclusions:
        return None
    every = [
        Truth((c[0], c[1]), inc.radius, c[2], inc.modulus / sample.modulus)
        for inc in sample.inclusions
        for c in (inc.center,)
    ]
    return dataclasses.replace(every[0], others=tuple(every[1:]))


def moved_scene(
    scene: SceneConfig, sample: SampleConfig, point: tuple[float, float]
) -> SceneConfig:
    """The scene whose one sample sits so that the tip, indenting where a single trial does,
    presses at ``point`` (m) of the patch: the inclusions' centres relative to that point. A
    world of the whole patch (``fidelity.inclusion_offsets: patch``) keeps the sample where it
    is and takes the point from the trial (``TrialSpec.at``): one factorisation a survey."""
    if scene.fidelity.inclusion_offsets == "patch":
        return scene
    moved = tuple(
        dataclasses.replace(
            inc,
            center_mm=(
                inc.center_mm[0] - point[0] / MM,
                inc.center_mm[1] - point[1] / MM,
                inc.center_mm[2],
            ),
        )
        for inc in sample.inclusions
    )
    return dataclasses.replace(scene, samples=(dataclasses.replace(sample, inclusions=moved),))


def probe_spec(
    scene: SceneConfig, sample: SampleConfig, k: int, point: tuple[float, float], seed: int
) -> TrialSpec:
    """The k-th probe's trial: the bench column at the campaign's first exposed length."""
    length = scene.campaign.exposed_lengths[0]
    return TrialSpec(
        trial_id=probe_name(k, point),
        kind="bench",
        sample=sample.name,
        modulus=sample.modulus,
        poisson=sample.poisson,
        tube=BENCH_COLUMN,
        orientation="downward",
        roll=0.0,
        exposed_length=length,
        seed=seed * 1_000_003 + k,
        at=point if scene.fidelity.inclusion_offsets == "patch" else (0.0, 0.0),
    )


def run_survey(
    scene: SceneConfig,
    stack: StackConfig,
    *,
    seed: int = 0,
    strategy: str | None = None,
    max_probes: int | None = None,
    run_dir: Path | None = None,
    on_probe: Callable[[Probe], None] | None = None,
    live: View | None = None,
) -> SurveyResult:
    """Run the scene's map campaign (``strategy`` and ``max_probes`` override its keys); with
    ``run_dir``, trial logs under ``logs/`` and the probes in ``probes.jsonl``, read back first
    (a resumed survey carries on from its last probe); with ``live``, each probe's trial and
    the map after it on the live view (``/map/grid``, ``/map/probes``)."""
    c = scene.campaign
    sample = scene.campaign_samples()[0]
    plan = SurveyPlan.of(
        c.patch_mm,
        strategy or c.strategy,
        max_probes if max_probes is not None else c.max_probes,
        threshold=c.map_threshold,
        seed=seed,
        tip_radius=stack.sensor.tip_radius,
    )
    logs = None if run_dir is None else run_dir / "logs"

    reach = ThroughRobot.of(scene, stack) if c.map_through == "robot" else None

    def probe_at(probes: list[Probe], point: Point) -> tuple[Probe, TrialOutcome | None]:
        return _probe_at(scene, stack, reach, probes, point, seed, logs, live)

    result = run_plan(
        plan, probe_at, run_dir=run_dir, on_probe=on_probe, live=live, truth=truth_of(sample)
    )
    result.reach = reach
    return result


def _probe_at(
    scene: SceneConfig,
    stack: StackConfig,
    reach: ThroughRobot | None,
    probes: list[Probe],
    point: tuple[float, float],
    seed: int,
    logs: Path | None,
    live: View | None,
) -> tuple[Probe, TrialOutcome | None]:
    """The next probe's trial at ``point``: on the bench column, the stage's travel to it from
    the last probe; or through the robot (``reach``: ``campaigns.throughrobot``), placed and
    pressed as a robot trial, the positioner's travel from the last probe's pose."""
    sample = scene.campaign_samples()[0]
    spec = probe_spec(scene, sample, len(probes), point, seed)
    placed = None if reach is None else reach.place(point)
    if reach is not None and placed is not None:
        if placed.status not in (0, 1):
            return refused(point, placed), None
        spec = reach.spec(spec, placed, point)
    o = run_sim_trial(
        spec,
        moved_scene(scene, sample, point),
        stack,
        transport=scene.transport,
        log_dir=logs,
        live=live,
    )
    last = (0.0, 0.0) if not probes else (probes[-1].x, probes[-1].y)
    if reach is None or placed is None:
        travel = math.hypot(point[0] - last[0], point[1] - last[1])
    else:
        travel = reach.travel(last if probes else None, placed)
    lab_time = o.sim_time + travel / scene.campaign.stage_speed
    probe = probe_of(o, point, lab_time, stack.sensor.tip_radius)
    if reach is None or placed is None:
        return probe, o
    indented = o.state != State.UNREACHABLE  # else the world's last contact was a touch
    error = o.true_misalignment if indented else None  # the world's truth
    probe = dataclasses.replace(probe, normal_error=error, tilt=measured_tilt(o))
    return oblique(probe, placed), o
