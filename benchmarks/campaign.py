"""Simulated campaigns: what each fidelity level costs and what it buys.

The bench-top campaign (Table I; every fifth trial with ``--quick``) runs serially in this
process at each fidelity level of :data:`LEVELS`: the shipped scene over the wire (emulators on
pseudo-terminals) and on the fast in-process path, each world effect the shipped scene leaves
off switched on (gravity, the realistic bus timing), the closed-form tissue instead of the FE
tables, lower control/board rates (20 Hz is cheap but no longer usable), and the cheapest
usable level ("lean": 25 Hz with the contact table on a 40 um grid,
``fidelity.contact_grid_um``). Per level: the CPU time of one trial (median over the trials;
``time.process_time``, so the emulators' threads count and other work on the machine does
not), how many times cheaper that is than the shipped level, simulated seconds per CPU second
("x real time per core"), the joint fit's median and worst relative error of E, its 95 %
interval coverage, the paper's single-point error and whether the level is still usable
(:func:`usable`). The table is the speed-against-error trade; the figure plots it with the
Pareto front of the usable levels.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import statistics
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from benchmarks.report import BenchContext, BenchSection, Table
from palpate.campaigns.campaign import (
    campaign_trials,
    median_abs_relative_error,
    run_campaign,
    warm_up,
)
from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.reports.verdicts import counts_column, tally
from palpate.sim.contact_table import equilibrium_on_grid
from palpate.simulation.trial import Transport, TrialOutcome

SceneChange = Callable[[SceneConfig], SceneConfig]


def _rate(hz: float) -> SceneChange:
    return lambda s: dataclasses.replace(s, control_rate_hz=hz, board_rate_hz=hz)


def _fidelity(**changes: Any) -> SceneChange:
    return lambda s: dataclasses.replace(s, fidelity=dataclasses.replace(s.fidelity, **changes))


def _shipped(s: SceneConfig) -> SceneConfig:
    return s


@dataclasses.dataclass(frozen=True)
class Level:
    name: str
    transport: Transport
    change: SceneChange


def _lean(hz: float, grid_um: float) -> SceneChange:
    """The control/board rate ``hz`` and the contact table on a ``grid_um`` grid."""
    rate, grid = _rate(hz), _fidelity(contact_grid_um=grid_um)
    return lambda s: grid(rate(s))


REFERENCE = "shipped (250 Hz, FE)"
CHEAPEST = "lean: 25 Hz, 40 um contact grid"
LEVELS = (
    Level(REFERENCE, "wire", _shipped),
    Level(REFERENCE, "fast", _shipped),
    Level("+ gravity", "fast", _fidelity(gravity=True)),
    Level(
        "+ realistic bus, 1 ms timer",
        "fast",
        _fidelity(bus_timing="realistic", latency_timer_ms=1.0),
    ),
    Level("closed-form tissue", "fast", _fidelity(tissue_model="closed-form")),
    Level("100 Hz", "fast", _rate(100.0)),
    Level("50 Hz", "fast", _rate(50.0)),
    Level("25 Hz", "fast", _rate(25.0)),
    Level("20 Hz", "fast", _rate(20.0)),
    Level(CHEAPEST, "fast", _lean(25.0, 40.0)),
)

# A level is usable when its joint fit still does its job on the campaign: the 95 % intervals
# cover the truth in at least 90 % of the trials and no estimate is off by more than 25 %.
USABLE_COVERAGE = 0.90
USABLE_WORST = 0.25


@dataclasses.dataclass(frozen=True)
class LevelRow:
    level: str
    transport: str
    trials: int
    cpu_per_trial: float  # median CPU seconds of one trial, serial
    real_time_per_core: float  # simulated seconds / CPU seconds over the campaign
    joint_median: float | None
    joint_worst: float | None
    coverage: float | None
    paper_median: float | None
    verdicts: str = ""  # ok/suspect/none counts, e.g. "53/2/0"


def _level_row(level: Level, ctx: BenchContext) -> LevelRow:
    scene = level.change(load(SceneConfig, resolve("scenes/bench.yaml")))
    stack = load_stack(resolve(scene.robot))
    specs = campaign_trials(scene, stack, ctx.seed)
    if ctx.quick:
        specs = specs[::5]
    # Each level pays for its own contact tables, as a fresh worker does: the levels run in one
    # process, and a level after another on the same samples and lengths would otherwise find
    # them cached (the 250 Hz fast level after the wire one: ~20 ms a trial less).
    equilibrium_on_grid.cache_clear()
    stamps = [time.process_time()]

    def progress(_: TrialOutcome) -> None:
        stamps.append(time.process_time())

    outcomes = run_campaign(specs, scene, stack, transport=level.transport, progress=progress)
    errors = [
        abs(m - o.spec.modulus) / o.spec.modulus
        for o in outcomes
        if (m := o.modulus("joint")) is not None
    ]
    covered = [o.joint is not None and o.joint.covers(o.spec.modulus) for o in outcomes]
    return LevelRow(
        level=level.name,
        transport=level.transport,
        trials=len(outcomes),
        cpu_per_trial=statistics.median(b - a for a, b in itertools.pairwise(stamps)),
        real_time_per_core=sum(o.sim_time for o in outcomes) / (stamps[-1] - stamps[0]),
        joint_median=median_abs_relative_error(outcomes),
        joint_worst=max(errors, default=None),
        coverage=sum(covered) / len(covered) if covered else None,  # as palpate.reports.methods
        paper_median=median_abs_relative_error(outcomes, "paper"),
        verdicts=counts_column(tally(outcomes)),
    )


def usable(row: LevelRow) -> bool:
    """Whether a level's estimates are still worth having (see USABLE_COVERAGE, USABLE_WORST)."""
    if row.coverage is None or row.joint_worst is None:
        return False
    return row.coverage >= USABLE_COVERAGE and row.joint_worst <= USABLE_WORST


def _pct(x: float | None) -> str:
    return "-" if x is None else f"{100 * x:.1f} %"


def _label(r: LevelRow) -> str:
    return f"{r.level}, {r.transport}"


def pareto_front(points: list[tuple[float, float]]) -> list[int]:
    """Indices of the points (cost, error) no other point beats in both (ties kept), by cost."""
    return sorted(
        (
            i
            for i, (c, e) in enumerate(points)
            if not any((c2 <= c and e2 <= e) and (c2 < c or e2 < e) for c2, e2 in points)
        ),
        key=lambda i: points[i],
    )


def _plot(rows: list[LevelRow], path: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    shown = [r for r in rows if r.joint_median is not None]
    points = [(1e3 * r.cpu_per_trial, 100 * (r.joint_median or 0.0)) for r in shown]
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for r, (x, y) in zip(shown, points, strict=True):
        ok = usable(r)
        ax.plot(x, y, ("o" if r.transport == "fast" else "s") if ok else "x")
        label = _label(r) if ok else f"{_label(r)}: NOT usable"
        ax.annotate(label, (x, y), fontsize=7, xytext=(3, 3), textcoords="offset points")
    # the front of the usable levels: a cheap level whose estimates are useless beats nothing
    kept = [p for r, p in zip(shown, points, strict=True) if usable(r)]
    front = [kept[i] for i in pareto_front(kept)]
    if front:
        ax.step(*zip(*front, strict=True), where="post", color="k", lw=0.8, label="Pareto front")
        ax.legend(fontsize=8)
    ax.set_xscale("log")
    ax.set_xlabel("CPU time per trial (ms, serial); x: not usable (coverage, worst error)")
    ax.set_ylabel("joint fit: median |relative error| of E (%)")
    ax.set_title("Simulated bench campaign: fidelity level, speed against error")
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def _table(rows: list[LevelRow], ctx: BenchContext) -> Table:
    ref = next(r for r in rows if r.level == REFERENCE and r.transport == "fast")
    return Table(
        title="Bench-top campaign (Table I) by fidelity level: speed against error",
        columns=[
            "level",
            "transport",
            "trials",
            "ok/sus/none",
            "CPU ms/trial",
            "x cheaper",
            "x real time/core",
            "joint median",
            "joint worst",
            "95% CI coverage",
            "paper median",
            "usable",
        ],
        rows=[
            [
                r.level,
                r.transport,
                r.trials,
                r.verdicts,
                1e3 * r.cpu_per_trial,
                ref.cpu_per_trial / r.cpu_per_trial,
                r.real_time_per_core,
                _pct(r.joint_median),
                _pct(r.joint_worst),
                _pct(r.coverage),
                _pct(r.paper_median),
                "yes" if usable(r) else "NO",
            ]
            for r in rows
        ],
        note=(
            f"serial, no trial logs, CPU time (process_time), seed {ctx.seed}"
            f"{', every fifth trial (--quick)' if ctx.quick else ''}; 'x cheaper' against the "
            "shipped level on the fast path; every level but the rates keeps 250 Hz; usable: "
            f"coverage >= {100 * USABLE_COVERAGE:.0f} % and worst error <= "
            f"{100 * USABLE_WORST:.0f} %"
        ),
    )


def run(ctx: BenchContext) -> BenchSection:
    warm_up()
    rows = [_level_row(level, ctx) for level in LEVELS]
    ref = next(r for r in rows if r.level == REFERENCE and r.transport == "fast")
    summary: dict[str, Any] = {
        _label(r): {
            k: (None if isinstance(v, float) and not math.isfinite(v) else v)
            for k, v in dataclasses.asdict(r).items()
        }
        for r in rows
    }
    cheapest = next(r for r in rows if r.level == CHEAPEST)
    summary["cheapest_vs_shipped"] = ref.cpu_per_trial / cheapest.cpu_per_trial
    summary["cheapest_usable"] = usable(cheapest)
    ctx.out_dir.mkdir(parents=True, exist_ok=True)  # only a section that draws makes it
    figure = _plot(rows, ctx.out_dir / "campaign_fidelity.png")
    return BenchSection(
        name="campaign", tables=[_table(rows, ctx)], figures=[figure], summary=summary
    )
