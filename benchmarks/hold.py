"""The hold after buckling: the relaxed modulus's accuracy against the hold's length.

On the shipped viscoelastic scenes (``config/scenes/viscoelastic/``: gels with a standard
linear solid, power-law tissue, and the same gels elastic as the control), one exposed length
(46 mm) and every speed the scene sweeps (0.1, 0.5, 2 mm/s), and on the relaxing lung-like
layers through the lung sensor (``config/scenes/lung/relaxing.yaml``, on the robot: one tube,
bent30, every orientation), each hold length of ``HOLDS_S``:
the trials that relax, the relaxed modulus's median and worst |error| (over every trial with a
number, and over ``ok``), its 95 % interval's coverage, the ``ok`` count, and the time a trial
costs (simulated: the stage's; wall: the simulator's, on the campaign's workers). ``--quick``:
two samples, the slowest and fastest speeds. The scenes ship with the hold this table chose
(docs/viscoelastic.md).
"""

from __future__ import annotations

import dataclasses
import statistics
import time
from collections.abc import Sequence
from typing import Any

from benchmarks.report import BenchContext, BenchSection, Table
from palpate.campaigns.campaign import campaign_trials, default_workers, run_campaign, warm_up
from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.reports.verdicts import relaxed_tally

HOLDS_S = (0.5, 1.0, 2.0, 5.0, 10.0)
SCENES = (
    "viscoelastic/gels",
    "viscoelastic/power-law",
    "viscoelastic/elastic-hold",
    "lung/relaxing",
)
ROBOT_TUBE = "bent30"


def hold_scene(base: SceneConfig, hold_s: float, quick: bool) -> SceneConfig:
    """``base`` at one hold length, one exposed length (46 mm on the bench; the robot's own,
    on one tube); with ``quick`` two samples and the slowest and fastest speeds."""
    c = base.campaign
    campaign = dataclasses.replace(
        c,
        hold_s=hold_s,
        indent_speeds_mm_per_s=_speeds(base, quick),
        samples=tuple(s.name for s in base.samples[:2]) if quick else c.samples,
    )
    if c.on_tubes:
        campaign = dataclasses.replace(campaign, tubes=(ROBOT_TUBE,))
    else:
        campaign = dataclasses.replace(campaign, exposed_lengths_mm=(46.0,))
    return dataclasses.replace(base, campaign=campaign)


def _pct(x: float | None) -> str:
    return "-" if x is None else f"{100 * x:.1f} %"


def hold_row(scene: SceneConfig, ctx: BenchContext) -> tuple[list[Any], dict[str, Any]]:
    stack = load_stack(resolve(scene.robot))
    start = time.perf_counter()
    specs = campaign_trials(scene, stack, ctx.seed)
    outcomes = run_campaign(specs, scene, stack, workers=default_workers())
    wall = (time.perf_counter() - start) / max(len(outcomes), 1)
    held = relaxed_tally(outcomes)
    r = held.numbers
    sim = statistics.median(o.sim_time for o in outcomes)
    coverage = "-" if r.coverage is None else f"{r.covered}/{r.numbers}"
    row = [
        f"{scene.campaign.hold_s:g}",
        held.held,
        held.relaxes,
        _pct(r.median_all),
        _pct(r.worst_all),
        coverage,
        f"{r.counts['ok']}",
        _pct(r.median_ok),
        sim,
        wall,
    ]
    return row, {**held.as_dict(), "sim_s": sim, "wall_s": wall}


def run(ctx: BenchContext) -> BenchSection:
    warm_up()
    tables: list[Table] = []
    summary: dict[str, Any] = {}
    for name in SCENES:
        base = load(SceneConfig, resolve(f"scenes/{name}.yaml"))
        rows: list[Sequence[Any]] = []
        for hold in HOLDS_S:
            row, summary[f"{name}/{hold:g}"] = hold_row(hold_scene(base, hold, ctx.quick), ctx)
            rows.append(row)
        tables.append(
            Table(
                title=f"Hold length against the relaxed modulus's error: {base.name}",
                columns=[
                    "hold s",
                    "trials",
                    "relax",
                    "median",
                    "worst",
                    "cover",
                    "ok",
                    "ok median",
                    "sim s/trial",
                    "wall s/trial",
                ],
                rows=rows,
                note=(
                    "|relative error| of the relaxed modulus against the world's (the truth); "
                    "median and worst over every trial with a number, cover: its 95 % interval "
                    f"holds the truth; {_where(base)}, speeds {scene_speeds(base, ctx.quick)} "
                    f"mm/s, seed {ctx.seed}; wall time on the campaign's workers"
                ),
            )
        )
    return BenchSection(name="hold", tables=tables, summary=summary)


def _where(base: SceneConfig) -> str:
    c = base.campaign
    if c.on_tubes:
        return f"L = {c.exposed_length_mm:g} mm on {ROBOT_TUBE}, every orientation"
    return "L = 46 mm"


def _speeds(base: SceneConfig, quick: bool) -> tuple[float, ...]:
    """The scene's speeds (mm/s); with ``quick`` the slowest and the fastest."""
    speeds = base.campaign.speeds_mm_per_s()
    return (speeds[0], speeds[-1]) if quick and len(speeds) > 1 else speeds


def scene_speeds(base: SceneConfig, quick: bool) -> str:
    return ", ".join(f"{v:g}" for v in _speeds(base, quick))
