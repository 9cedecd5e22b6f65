"""What probing a tilted sample costs on this drive, and its floor with the surface known.

Probing (``robot.probing``) touches the surface at four rolls of the bent tube, fits the plane
and turns the sensor orthogonal to it. Its time goes to seeks at the speed the stage can stop
from, retracts behind where the surface can be before each roll, and the rolls themselves. This
section runs a fixed subset of the tilted scene (``config/scenes/tilted.yaml``: every 7th
trial, spanning tilts, tubes and orientations; every 19th with ``--quick``) at:

- the shipped routine;
- three touches, the full roll step either side of the plan (the fewest a plane needs; the
  shipped pattern's quarter step first gives the surface's slope before the wide move);
- the routine told the true surface (:class:`ExactSurfaceGeometry`): each next touch predicted
  exactly, with no slack, so every retract is only the clearance. No prediction can do better,
  so its time is the floor of the four-touch pattern on this drive; the fit and the re-plan
  still use the touches, so the residual is what the touches give;
- the same with three touches (the full roll step on either side), the fewest a plane needs;
- the same with every drive limit doubled (stage and roll speed and acceleration), with four
  touches and with three.

Per row: trials done, the probing time (simulated) median / min / max, the true residual at
indentation (the world's angle between the sensor and the normal) and the joint fit's median
|relative error| of E. Every row but the shipped one replaces two functions of
``palpate.simulation.trial`` for the duration (``benchmarks.patching``); shipped code has no
hook for it.
"""

from __future__ import annotations

import dataclasses
import math
import statistics
from collections.abc import Callable
from typing import Any

from benchmarks.patching import patched
from benchmarks.report import BenchContext, BenchSection, Table
from palpate.campaigns.campaign import (
    campaign_trials,
    median_abs_relative_error,
    run_campaign,
    warm_up,
)
from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.config.schema import StackConfig
from palpate.estimation.pose.surface import SurfaceGeometry
from palpate.robot.probe_plan import ProbeGeometry, ProbeSettings
from palpate.robot.probe_result import Touch
from palpate.robot.probing import ProbeRoutine
from palpate.sim.world import Surface
from palpate.simulation import trial as sim_trial
from palpate.simulation.trial import TrialOutcome
from palpate.simulation.world import TrialGeometry

SCENE = "scenes/tilted.yaml"
STRIDE, QUICK_STRIDE = 7, 19  # coprime to the 3 orientations and 3 tubes: a spread subset


class ExactSurfaceGeometry(ProbeGeometry):
    """A trial's probe geometry told the true surface: the next touch is predicted where the
    ray meets it, past it by the touches' depth, with no slack (and so are the sweeps' safe
    advances, which come from the prediction)."""

    def __init__(self, base: ProbeGeometry, surface: Surface) -> None:
        self.__dict__.update(vars(base))  # the same tube, limits and strain model
        tissue = SurfaceGeometry.make(surface.point, surface.normal, surface.radius)
        self.centres = tissue.offset(base.tip_radius)  # where the tip's centre touches

    def predict(
        self, touches: list[Touch], roll: float, settings: ProbeSettings
    ) -> tuple[float, float]:
        held = [t.depth for t in touches if not t.slipped] or [0.0]
        return self.advance_to(self.centres, roll) + statistics.fmean(held), 0.0


@dataclasses.dataclass(frozen=True)
class Variant:
    name: str
    exact: bool = False
    touches: int = 4
    drive_scale: float = 1.0


VARIANTS = (
    Variant("shipped"),
    Variant("3 touches (the full step either side)", touches=3),
    Variant("exact surface", exact=True),
    Variant("exact surface, 3 touches", exact=True, touches=3),
    Variant("exact surface, drive limits x2", exact=True, drive_scale=2.0),
    Variant("exact surface, 3 touches, drive limits x2", exact=True, touches=3, drive_scale=2.0),
)


def faster_drive(stack: StackConfig, scale: float) -> StackConfig:
    """The stack with the stage's and the roll's speed and acceleration limits times ``scale``."""
    d = stack.drive
    drive = dataclasses.replace(
        d,
        max_speed_mm_per_s=d.max_speed_mm_per_s * scale,
        max_roll_speed_deg_per_s=d.max_roll_speed_deg_per_s * scale,
        max_accel_mm_per_s2=d.max_accel_mm_per_s2 * scale,
        max_roll_accel_deg_per_s2=d.max_roll_accel_deg_per_s2 * scale,
    )
    return dataclasses.replace(stack, drive=drive)


def _three_touches(routine: ProbeRoutine) -> ProbeRoutine:
    """``routine`` touching the plan and the full step either side of it (the shipped
    pattern's second offset is its full step)."""
    step = routine.settings.offsets[1]
    routine.settings = dataclasses.replace(routine.settings, offsets=(step, -step))
    routine.rolls = routine.geometry.probe_rolls(routine.plan.roll, routine.settings.offsets)
    return routine


def prober_hooks(exact: bool, touches: int = 4) -> list[tuple[Any, str, Callable[[Any], Any]]]:
    """Replacements (for :func:`benchmarks.patching.patched`) that change what each
    trial's prober is: told the trial's true surface (``exact``; the trial's geometry is kept as
    it is planned), and/or three touches instead of four. The prober factory wraps what it
    builds."""
    seen: list[TrialGeometry] = []

    def keep_geometry(original: Callable[..., TrialGeometry]) -> Callable[..., TrialGeometry]:
        def planned(*args: Any, **kwargs: Any) -> TrialGeometry:
            seen.append(original(*args, **kwargs))
            return seen[-1]

        return planned

    def changed(routine: ProbeRoutine) -> ProbeRoutine:
        if exact:
            routine.geometry = ExactSurfaceGeometry(routine.geometry, seen[-1].surface)
        return _three_touches(routine) if touches == 3 else routine

    def prober(original: Callable[..., Any]) -> Callable[..., Any]:
        def factory(*args: Any, **kwargs: Any) -> Any:
            build = original(*args, **kwargs)
            return None if build is None else lambda plan: changed(build(plan))

        return factory

    return [
        (sim_trial, "trial_geometry", keep_geometry),
        (sim_trial, "prober_for", prober),
    ]


@dataclasses.dataclass(frozen=True)
class Row:
    name: str
    outcomes: list[TrialOutcome]

    @property
    def probing(self) -> list[float]:
        return [o.probing_time for o in self.outcomes if o.state == "done"]

    @property
    def residual_max(self) -> float | None:
        r = [o.true_misalignment for o in self.outcomes if o.true_misalignment is not None]
        return math.degrees(max(r)) if r else None


def run_variant(variant: Variant, specs: list[Any], scene: SceneConfig, stack: StackConfig) -> Row:
    stack = faster_drive(stack, variant.drive_scale) if variant.drive_scale != 1.0 else stack
    changed = variant.exact or variant.touches != 4
    hooks = prober_hooks(variant.exact, variant.touches) if changed else []
    with patched(hooks):
        outcomes = run_campaign(specs, scene, stack)
    return Row(variant.name, outcomes)


def trial_subset(quick: bool, seed: int) -> tuple[list[Any], SceneConfig, StackConfig]:
    scene = load(SceneConfig, resolve(SCENE))
    stack = load_stack(resolve(scene.robot))
    specs = campaign_trials(scene, stack, seed)
    return specs[:: QUICK_STRIDE if quick else STRIDE], scene, stack


def _table(rows: list[Row], ctx: BenchContext) -> Table:
    def stat(xs: list[float], f: Callable[[list[float]], float]) -> float | str:
        return f(xs) if xs else "-"

    def pct(x: float | None) -> str:
        return "-" if x is None else f"{100 * x:.1f} %"

    return Table(
        title="Probing the tilted scene: time on this drive, and its floor with the surface known",
        columns=["variant", "done", "probing s median", "min", "max", "residual max deg", "joint"],
        rows=[
            [
                r.name,
                f"{sum(o.state == 'done' for o in r.outcomes)}/{len(r.outcomes)}",
                stat(r.probing, statistics.median),
                stat(r.probing, min),
                stat(r.probing, max),
                "-" if r.residual_max is None else r.residual_max,
                pct(median_abs_relative_error(r.outcomes)),
            ]
            for r in rows
        ],
        note=(
            f"{len(rows[0].outcomes)} trials of {SCENE} (every "
            f"{QUICK_STRIDE if ctx.quick else STRIDE}th), seed {ctx.seed}; simulated seconds; "
            "residual: the world's angle between sensor and normal at indentation; joint: the "
            "joint fit's median |relative error| of E. Exact surface: every next touch predicted "
            "where the ray meets the true surface, no slack."
        ),
    )


def run(ctx: BenchContext) -> BenchSection:
    warm_up()
    specs, scene, stack = trial_subset(ctx.quick, ctx.seed)
    rows = [run_variant(v, specs, scene, stack) for v in VARIANTS]
    summary = {
        r.name: {
            "done": sum(o.state == "done" for o in r.outcomes),
            "trials": len(r.outcomes),
            "probing_s_median": statistics.median(r.probing) if r.probing else None,
            "residual_max_deg": r.residual_max,
        }
        for r in rows
    }
    return BenchSection(name="probing", tables=[_table(rows, ctx)], summary=summary)
