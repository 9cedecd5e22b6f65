"""Coverage study: N seeded repeats of a scene's campaign; error and interval coverage with bounds.

Every trial of the scene's campaign is run ``--repeats`` times, each with its own seed (the
campaign's repeats, seeded per trial as ``palpate sim`` seeds them), through any executor. The
report gives, per sample and over all trials, for the joint fit and for the paper's estimate: the
fraction of trials with a number, the median and 95th percentile of |relative error| with
distribution-free 95 % bounds (order statistics), the worst |relative error| seen, and for the joint
fit the fraction of its intervals that hold the true modulus with a Wilson 95 % interval
(``palpate/campaigns/study.py``). Trials stream their results as they finish (``--results FILE``:
one JSON line per trial); trial logs only with ``--logs DIR``; a progress bar only on a terminal.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import logging
import time
from collections.abc import Callable
from pathlib import Path
from typing import IO, Any

from palpate.argtypes import non_negative_int, positive_int
from palpate.campaigns.campaign import CampaignRun, campaign_trials, default_workers, run_campaigns
from palpate.campaigns.executors import add_executor_arguments, open_executor
from palpate.campaigns.study import Bounded, GroupStats, MethodStats, TrialErrors, summarize_study
from palpate.config import load, load_stack, resolve
from palpate.config.loader import InputError
from palpate.config.scene import SceneConfig
from palpate.progress import progress_bar
from palpate.simulation.preflight import check_campaign, check_reachable
from palpate.simulation.trial import TrialOutcome

log = logging.getLogger("palpate")


def register(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--campaign", choices=("bench", "robot"), default="bench", help="a shipped scene"
    )
    parser.add_argument("--scene", type=Path, help="a scene YAML (overrides --campaign)")
    parser.add_argument(
        "--repeats",
        type=positive_int,
        default=10,
        help="seeded repeats of every trial of the campaign",
    )
    parser.add_argument(
        "--seed", type=non_negative_int, default=0, help="makes the study reproducible"
    )
    parser.add_argument(
        "--workers", type=positive_int, default=default_workers(), help="trials run in parallel"
    )
    add_executor_arguments(parser)
    parser.add_argument(
        "--results", type=Path, help="append one JSON line per trial here as trials finish"
    )
    parser.add_argument("--logs", type=Path, help="write every trial's log in this folder")


def study_scene(scene: SceneConfig, repeats: int) -> SceneConfig:
    """The scene with its campaign repeated ``repeats`` times over (trial ids end in r<k>)."""
    if repeats < 1:
        raise InputError(f"--repeats must be >= 1, got {repeats}")
    campaign = dataclasses.replace(scene.campaign, repeats=scene.campaign.repeats * repeats)
    return dataclasses.replace(scene, campaign=campaign)


def trial_errors(o: TrialOutcome) -> TrialErrors:
    jf = o.joint
    return TrialErrors(
        sample=o.spec.sample,
        truth=o.spec.modulus,
        joint=o.modulus("joint"),
        joint_low=None if jf is None else jf.ci_low,
        joint_high=None if jf is None else jf.ci_high,
        paper=o.modulus("paper"),
    )


def run(args: argparse.Namespace) -> int:
    path = Path(args.scene) if args.scene else resolve(f"scenes/{args.campaign}.yaml")
    base = load(SceneConfig, path)
    stack = load_stack(resolve(base.robot))
    check_campaign(base, stack, str(path), str(resolve(base.robot)))
    scene = study_scene(base, args.repeats)
    specs = campaign_trials(scene, stack, args.seed)
    check_reachable(specs, stack, str(path), str(resolve(scene.robot)))
    if args.logs is not None:
        args.logs.mkdir(parents=True, exist_ok=True)
    bar = progress_bar(len(specs), f"{scene.name} study")
    stream: IO[str] | None = None
    if args.results is not None:
        args.results.parent.mkdir(parents=True, exist_ok=True)
        stream = args.results.open("a", encoding="utf-8")
    t0 = time.perf_counter()
    try:
        run_ = CampaignRun(specs, scene, stack, scene.transport, args.logs)
        with open_executor(args.executor, max(1, args.workers), args.scheduler) as executor:
            result = run_campaigns([run_], executor=executor, progress=_progress(bar, stream))
    finally:
        bar.close()
        if stream is not None:
            stream.close()
    wall = time.perf_counter() - t0
    outcomes = result[0].outcomes
    summary = summarize_study(trial_errors(o) for o in outcomes)
    sim_time = sum(o.sim_time for o in outcomes)
    payload: dict[str, Any] = {
        "scene": scene.name,
        "transport": scene.transport,
        "repeats": args.repeats,
        "seed": args.seed,
        "trials": len(outcomes),
        "executor": args.executor,
        "workers": args.workers,
        "wall_s": wall,
        "simulated_s": sim_time,
        **summary.as_dict(),
    }
    if args.json:
        print(json.dumps(payload, indent=2))
    else:
        _print(summary.per_sample + ([summary.overall] if summary.overall else []))
        print(
            f"\n{len(outcomes)} trials ({args.repeats} repeats of {len(outcomes) // args.repeats}"
            f", {args.executor} executor, {args.workers} worker(s)) in {wall:.1f} s wall for "
            f"{sim_time:.1f} s simulated; bounds: 95 % (Wilson for fractions, order statistics "
            "for quantiles; the worst error has none)"
        )
    return 0 if any(o.state == "done" for o in outcomes) else 1


def _progress(bar: Any, stream: IO[str] | None) -> Callable[[TrialOutcome], None]:
    def progress(o: TrialOutcome) -> None:
        bar.update(1)
        if stream is not None:
            stream.write(json.dumps(o.as_dict(), separators=(",", ":")) + "\n")
            stream.flush()

    return progress


def _pct(b: Bounded | None) -> str:
    if b is None or b.value is None:
        return "-"

    def f(v: float | None) -> str:
        return "?" if v is None else f"{100 * v:.1f}"

    return f"{100 * b.value:.1f} [{f(b.low)},{f(b.high)}]"


def _line(g: GroupStats, m: MethodStats) -> str:
    worst = "-" if m.max_abs_rel_error is None else f"{100 * m.max_abs_rel_error:.1f}"
    return (
        f"{g.name:>8} {m.trials:>6} {_pct(m.with_number):>20} {_pct(m.median_abs_rel_error):>20} "
        f"{_pct(m.p95_abs_rel_error):>20} {worst:>7} {_pct(m.coverage):>20}"
    )


def _print(groups: list[GroupStats]) -> None:
    cols = [("sample", 8), ("trials", 6), ("with number %", 20), ("median |err| %", 20)]
    cols += [("p95 |err| %", 20), ("worst %", 7), ("coverage %", 20)]
    head = " ".join(f"{c:>{w}}" for c, w in cols)
    titles = {
        "joint": "joint fit (its interval's coverage of the true modulus)",
        "paper": "the paper's estimate (Eqs. 13-14; no interval)",
    }
    for method, title in titles.items():
        print(f"{title}: value [95 % bounds]")
        print(head)
        print("-" * len(head))
        for g in groups:
            print(_line(g, g.joint if method == "joint" else g.paper))
        print()
