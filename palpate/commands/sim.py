"""Run a simulated campaign (the paper's robot or bench-top experiment): no hardware needed."""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import json
import logging
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from palpate.argtypes import non_negative_int, positive_int
from palpate.calibration import config_lines
from palpate.campaigns.campaign import (
    CampaignRun,
    SampleRow,
    campaign_trials,
    default_workers,
    median_abs_relative_error,
    run_campaigns,
    summarize_campaign,
)
from palpate.campaigns.executors import add_executor_arguments, open_executor
from palpate.campaigns.resume import resume_outcomes
from palpate.campaigns.runs import fingerprint, locked, new_run_dir, resumable, write_run_info
from palpate.config import InputError, load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.config.schema import StackConfig
from palpate.exitcodes import EXIT_FAULT, EXIT_OK
from palpate.live import add_live_argument, live_view
from palpate.progress import progress_bar
from palpate.reports import verdicts
from palpate.reports.campaign_table import print_table
from palpate.reports.payload import campaign_report
from palpate.reports.results import CampaignResults
from palpate.simulation.preflight import check_campaign, check_reachable
from palpate.simulation.trial import Transport, TrialOutcome, TrialSpec
from palpate.simulation.world import tissue_description

log = logging.getLogger(__name__)

CAMPAIGNS = {"robot": ("robot",), "bench": ("bench",), "paper": ("bench", "robot")}


def register(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--campaign",
        choices=sorted(CAMPAIGNS),
        default="robot",
        help="a shipped scene; paper: both (bench then robot) through one pool",
    )
    parser.add_argument("--scene", type=Path, help="a scene YAML (overrides --campaign)")
    parser.add_argument(
        "--seed", type=non_negative_int, default=0, help="makes the run reproducible"
    )
    parser.add_argument(
        "--out",
        type=Path,
        default=Path("out/sim"),
        help="each run writes its logs and plots to a new folder OUT/<scene>/<date-time>/",
    )
    parser.add_argument(
        "--workers",
        type=positive_int,
        default=default_workers(),
        help="trials run in parallel (processes, threads or local Dask workers)",
    )
    add_executor_arguments(parser)
    parser.add_argument(
        "--wire", action="store_true", help="servos and board over ptys (the hardware path)"
    )
    parser.add_argument("--limit", type=positive_int, help="run only the first N trials")
    parser.add_argument(
        "--resume",
        action="store_true",
        help="continue the newest run of the same command under --out (a run killed mid-way): "
        "its complete trials are read from their logs, the rest run",
    )
    parser.add_argument("--no-plots", action="store_true", help="do not write the PNG plots")
    parser.add_argument(
        "--no-mcap", action="store_true", help="no MCAP recording beside each trial's log"
    )
    add_live_argument(parser, "each trial, one at a time (a serial executor)")
    parser.add_argument(
        "--faults",
        action="store_true",
        help="the fault campaign: the scene's fault cases (default scene: scenes/faults.yaml); "
        "prints fault, trials, safe stops, data kept (palpate/faults/)",
    )
    parser.add_argument(
        "--compare-methods",
        action="store_true",
        help="the paper's estimate vs the joint fit on the same trials, contact errors 0, "
        "+-0.1, +-0.3 mm (palpate/reports/methods.py)",
    )
    parser.add_argument(
        "--compare-paper",
        action="store_true",
        help="the paper's method beside the paper's Table I (bench) or II (robot): per-sample "
        "rows and the error structure (palpate/reports/papertables.py)",
    )


@dataclass
class _Campaign:
    """One scene's campaign, loaded and checked before anything runs."""

    path: Path
    scene: SceneConfig
    stack: StackConfig
    specs: list[TrialSpec]
    transport: Transport
    run_dir: Path = Path()
    done: dict[str, TrialOutcome] = field(default_factory=dict)  # read back on --resume
    outcomes: list[TrialOutcome] = field(default_factory=list)
    wall: float = 0.0
    results: CampaignResults = field(default_factory=lambda: CampaignResults(Path()))

    @property
    def log_dir(self) -> Path:
        return self.run_dir / "logs"

    def to_run(self) -> list[TrialSpec]:
        return [s for s in self.specs if s.trial_id not in self.done]


def run(args: argparse.Namespace) -> int:
    """Exit 0 when every trial ended as planned (DONE), 1 when any did not (the tables are
    printed all the same), 2 on bad input (see docs/reliability.md)."""
    if args.faults:
        from palpate.faults import run_command

        return run_command(args)
    if args.scene:
        paths = [Path(args.scene)]
    else:
        paths = [resolve(f"scenes/{name}.yaml") for name in CAMPAIGNS[args.campaign]]
    # every scene is loaded and checked first: a bad one stops the run before any trial moves
    campaigns = [_prepare(path, args) for path in paths]
    with contextlib.ExitStack() as locks:
        for c in campaigns:
            _open_run(c, args, locks)
        wall_all = _run(campaigns, args)
        if args.compare_methods:
            _compare(campaigns, args)
        elif args.compare_paper:
            _compare_paper(campaigns, args)
        else:
            _print_results(campaigns, args, wall_all)
    faulted = any(o.state != "done" for c in campaigns for o in c.outcomes)
    return EXIT_FAULT if faulted else EXIT_OK


def _run(campaigns: list[_Campaign], args: argparse.Namespace) -> float:
    """Run every campaign's remaining trials through one pool; fills outcomes and wall times."""
    total = sum(len(c.to_run()) for c in campaigns)
    bar = progress_bar(total, "campaign")

    by_logs = {c.log_dir: c for c in campaigns}

    def progress(o: TrialOutcome) -> None:
        bar.update(1)
        bar.set_postfix_str(o.spec.trial_id)
        c = by_logs.get(Path(o.log_path).parent) if o.log_path else None
        if c is not None:  # each trial's row on disk as it finishes
            c.results.add(o.as_dict())

    runs = [
        CampaignRun(
            c.to_run(),
            c.scene,
            c.stack,
            c.transport,
            c.log_dir,
            _series_for(c, args),
            prior=list(c.done.values()),
        )
        for c in campaigns
    ]
    bar.set_description(" + ".join(c.scene.name for c in campaigns) + " campaign")
    t_all = time.perf_counter()
    if args.live is not None:  # the live view shows one trial at a time
        args.executor, args.workers = "serial", 1
    with (
        live_view(args.live, campaigns[0].stack) as live,
        open_executor(args.executor, max(1, args.workers), args.scheduler) as executor,
    ):
        runs = [dataclasses.replace(r, live=live) for r in runs]
        results = run_campaigns(runs, executor=executor, progress=progress)  # one pool for all
    wall_all = time.perf_counter() - t_all
    bar.close()
    before = 0.0
    for c, r in zip(campaigns, results, strict=True):
        # the pool overlaps campaigns: each is charged the wall time since the previous finished
        c.wall, before = max(r.finished_s - before, 1e-9), r.finished_s
        ran = {o.spec.trial_id: o for o in r.outcomes}
        c.outcomes = [ran.get(s.trial_id) or c.done[s.trial_id] for s in c.specs]
    return wall_all


def _series_for(c: _Campaign, args: argparse.Namespace) -> str | None:
    """The trial whose force and strain series the traces plot shows (the first), if it runs."""
    first = c.specs[0].trial_id
    return None if args.no_plots or first in c.done else first


def _print_results(campaigns: list[_Campaign], args: argparse.Namespace, wall_all: float) -> None:
    payloads = [_report(c, args) for c in campaigns]
    sim_all = sum(o.sim_time for c in campaigns for o in c.outcomes)
    if args.json:
        if len(payloads) == 1:
            print(json.dumps(payloads[0], indent=2))
        else:
            print(json.dumps({"campaigns": payloads, "wall_s": wall_all}, indent=2))
    elif len(campaigns) > 1:
        total = sum(len(c.outcomes) for c in campaigns)
        print(
            f"all {total} trials in {wall_all:.1f} s wall for {sim_all:.1f} s simulated: "
            f"{sim_all / wall_all:.1f}x real time (one pool for all: each campaign's wall time "
            "above runs from the previous campaign's last trial)"
        )


def _prepare(path: Path, args: argparse.Namespace) -> _Campaign:
    scene = load(SceneConfig, path)
    if args.no_mcap:
        scene = dataclasses.replace(scene, mcap=False)
    stack = load_stack(resolve(scene.robot))
    check_campaign(scene, stack, str(path), str(resolve(scene.robot)))
    specs = campaign_trials(scene, stack, args.seed)
    if args.limit:
        specs = specs[: args.limit]
    if not specs:
        raise InputError(f"{path}: the campaign has no trials")
    check_reachable(specs, stack, str(path), str(resolve(scene.robot)))
    transport: Transport = "wire" if args.wire else scene.transport
    return _Campaign(path, scene, stack, specs, transport)


def _open_run(c: _Campaign, args: argparse.Namespace, locks: contextlib.ExitStack) -> None:
    """The campaign's run folder: a new one, or with ``--resume`` the newest one of the same
    run, locked while this process writes there; on resume, its complete trials read back."""
    info = {
        "scene": c.scene.name,
        "config": fingerprint(c.scene, c.stack),
        "seed": args.seed,
        "limit": args.limit,
        "transport": c.transport,
        "trials": len(c.specs),
    }
    base = args.out / c.scene.name
    if args.resume:
        c.run_dir = locks.enter_context(locked(resumable(base, info)))
        c.done = resume_outcomes(c.log_dir, c.specs, c.stack)
        c.results = CampaignResults(c.run_dir)
        c.results.start(o.as_dict() for s in c.specs if (o := c.done.get(s.trial_id)))
        log.info(
            "resuming %s: %d of %d trials already complete", c.run_dir, len(c.done), len(c.specs)
        )
    else:
        c.run_dir = locks.enter_context(locked(new_run_dir(base)))
        write_run_info(c.run_dir, info)
        c.results = CampaignResults(c.run_dir)
    c.log_dir.mkdir(exist_ok=True)


def _compare(campaigns: list[_Campaign], args: argparse.Namespace) -> None:
    from palpate.reports.methods import compare_methods, comparison_payload, print_comparison
    from palpate.robot.trial.setup import sensor_section

    for c in campaigns:
        table = compare_methods(c.outcomes, c.stack, sensor_section(c.stack))
        if args.json:
            print(json.dumps(comparison_payload(table, c.scene.name, args.seed), indent=2))
        else:
            print_comparison(table, c.scene.name)


def _compare_paper(campaigns: list[_Campaign], args: argparse.Namespace) -> None:
    from palpate.reports.papertables import comparison, print_comparison

    payloads = []
    for c in campaigns:
        data = comparison(c.outcomes, c.scene.campaign.kind, c.scene.campaign.outlier_above)
        payloads.append({"scene": c.scene.name, "seed": args.seed, **data})
        if not args.json:
            print_comparison(data, c.scene.name, args.seed)
            print()
    if args.json:
        print(json.dumps(payloads[0] if len(payloads) == 1 else {"campaigns": payloads}, indent=2))


def _figures(c: _Campaign, rows: list[SampleRow]) -> list[str]:
    """The campaign's figures (matplotlib is imported here: 0.3 s a run that draws none)."""
    from palpate.reports.plots import campaign_figures

    return campaign_figures(c.outcomes, rows, c.run_dir, c.scene.name)


def _report(c: _Campaign, args: argparse.Namespace) -> dict[str, object]:
    """Print one campaign's table (unless ``--json``), write its results into the run folder
    (``palpate.reports.results``) and return its JSON payload."""
    rows = summarize_campaign(c.outcomes, c.scene.campaign.outlier_above)
    figures = [] if args.no_plots else _figures(c, rows)
    run = {
        "run_dir": str(c.run_dir),
        "log_dir": str(c.log_dir),
        "transport": c.transport,
        "seed": args.seed,
    }
    report = campaign_report(c.scene, c.stack, c.outcomes, run=run, wall=c.wall, figures=figures)
    payload = report.as_dict()
    files = c.results.finish(payload["trials"], report.samples, payload)
    if not args.json:
        _print_report(
            c, args, report.samples, report.calibration, figures + [str(f) for f in files]
        )
    return payload


def _print_report(
    c: _Campaign,
    args: argparse.Namespace,
    records: list[dict[str, Any]],
    found: dict[str, tuple[float, float]],
    files: list[str],
) -> None:
    """One campaign's table and summary lines, as a person reads them."""
    scene, outcomes, wall = c.scene, c.outcomes, c.wall
    sim_time = sum(o.sim_time for o in outcomes)
    paper = median_abs_relative_error(outcomes, "paper")
    failed = [o for o in outcomes if o.state != "done"]
    print_table(c.scene.name, records)
    samples = c.scene.campaign_samples()
    levels = sorted({tissue_description(scene, c.stack, s.name)["level"] for s in samples})
    note = " (the estimator's own model: this judges self-consistency)" * ("closed-form" in levels)
    print(f"world tissue: {', '.join(levels)}{note}")
    held = [s.name for s in samples if s.inclusions]
    if held:
        print(
            f"inclusions in {', '.join(held)}: each estimate is the apparent modulus at the "
            "indented point (the estimator is not told); 'true' is the matrix's "
            "(docs/inclusions.md)"
        )
    print()
    threshold = scene.campaign.classify_at
    for line in verdicts.summary_lines(outcomes) + verdicts.classified_line(outcomes, threshold):
        print(line)
    for line in config_lines(found):
        print(f"calibrated on the rigid reference: {line}")
    if paper is not None:
        print(f"  the paper's single-point estimate on the same trials: {100 * paper:.1f} %")
    print(
        f"{len(outcomes)} trials ({c.transport} path, {args.executor} executor, "
        f"{args.workers} worker(s)) in {wall:.1f} s "
        f"wall for {sim_time:.1f} s simulated: {sim_time / wall:.1f}x real time"
    )
    for o in failed:
        print(f"  trial {o.spec.trial_id}: {o.state}: {o.reason}")
    print(f"run folder: {c.run_dir}")
    print(f"logs: {c.log_dir}")
    for f in files:
        print(f"{'plot' if f.endswith('.png') else 'results'}: {f}")
    print()
