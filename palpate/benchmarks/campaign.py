"""Simulated campaigns: what the control rate costs and what it buys.

The simulator runs the control loop, the servo bus and the FBG stream at the scene's
``control_rate_hz`` (the board streams at the same rate, as the shipped scenes do), so the
rate sets both the CPU a trial costs and the number of samples the estimators see. This
section runs the bench-top campaign (Table I; every fifth trial with ``--quick``) at a few
rates, serially in this process, and reports per trial the median wall time and, over the
trials, the joint fit's median and worst relative error of E, its interval coverage and the
paper's single-point error. The shipped scenes use 250 Hz.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import statistics
import time
from pathlib import Path
from typing import Any

from config import load, load_stack, resolve
from config.scene import SceneConfig
from palpate.benchmarks.report import BenchContext, BenchSection, Table
from palpate.campaign import campaign_trials, median_abs_relative_error, run_campaign, warm_up
from palpate.simtrial import TrialOutcome

RATES_HZ = (100.0, 250.0, 500.0)


@dataclasses.dataclass(frozen=True)
class RateRow:
    rate_hz: float
    trials: int
    seconds_per_trial: float  # median wall time of one trial, serial
    speedup: float  # simulated / wall seconds over the campaign
    joint_median: float | None
    joint_worst: float | None
    coverage: float | None
    paper_median: float | None


def _rate_row(rate_hz: float, ctx: BenchContext) -> RateRow:
    scene = load(SceneConfig, resolve("scenes/bench.yaml"))
    scene = dataclasses.replace(scene, control_rate_hz=rate_hz, board_rate_hz=rate_hz)
    stack = load_stack(resolve(scene.robot))
    specs = campaign_trials(scene, stack, ctx.seed)
    if ctx.quick:
        specs = specs[::5]
    stamps = [time.perf_counter()]

    def progress(_: TrialOutcome) -> None:
        stamps.append(time.perf_counter())

    outcomes = run_campaign(specs, scene, stack, progress=progress)  # serial: times are per trial
    per_trial = [b - a for a, b in itertools.pairwise(stamps)]
    errors = [
        abs(m - o.spec.modulus) / o.spec.modulus
        for o in outcomes
        if (m := o.modulus("joint")) is not None
    ]
    covered = [o.joint is not None and o.joint.covers(o.spec.modulus) for o in outcomes]
    return RateRow(
        rate_hz=rate_hz,
        trials=len(outcomes),
        seconds_per_trial=statistics.median(per_trial),
        speedup=sum(o.sim_time for o in outcomes) / (stamps[-1] - stamps[0]),
        joint_median=median_abs_relative_error(outcomes),
        joint_worst=max(errors, default=None),
        coverage=sum(covered) / len(covered) if covered else None,  # as palpate.compare
        paper_median=median_abs_relative_error(outcomes, "paper"),
    )


def _pct(x: float | None) -> str:
    return "-" if x is None else f"{100 * x:.1f} %"


def _plot(rows: list[RateRow], path: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    for r in rows:
        if r.joint_median is None:
            continue
        ax.plot(r.seconds_per_trial, 100 * r.joint_median, "o")
        ax.annotate(f"{r.rate_hz:g} Hz", (r.seconds_per_trial, 100 * r.joint_median), fontsize=8)
    ax.set_xlabel("wall time per trial (s, serial)")
    ax.set_ylabel("joint fit: median |relative error| of E (%)")
    ax.set_title("Simulated bench campaign: control rate, speed against error")
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def run(ctx: BenchContext) -> BenchSection:
    warm_up()
    rows = [_rate_row(rate, ctx) for rate in RATES_HZ]
    table = Table(
        title="Bench-top campaign (Table I) by control rate: speed against error",
        columns=[
            "rate Hz",
            "trials",
            "s/trial (median)",
            "x real time",
            "joint median",
            "joint worst",
            "95% CI coverage",
            "paper median",
        ],
        rows=[
            [
                f"{r.rate_hz:g}",
                r.trials,
                r.seconds_per_trial,
                r.speedup,
                _pct(r.joint_median),
                _pct(r.joint_worst),
                _pct(r.coverage),
                _pct(r.paper_median),
            ]
            for r in rows
        ],
        note=(
            "serial, in-process fast path, seed "
            f"{ctx.seed}{', every fifth trial (--quick)' if ctx.quick else ''}; "
            "the shipped scenes use 250 Hz"
        ),
    )
    summary: dict[str, Any] = {
        f"{r.rate_hz:g}_hz": {
            k: (None if isinstance(v, float) and not math.isfinite(v) else v)
            for k, v in dataclasses.asdict(r).items()
        }
        for r in rows
    }
    figure = _plot(rows, ctx.out_dir / "campaign_rate.png")
    return BenchSection(name="campaign", tables=[table], figures=[figure], summary=summary)
