"""Run a simulated campaign (the paper's robot or bench-top experiment): no hardware needed."""

from __future__ import annotations

import argparse
import dataclasses
import json
from pathlib import Path

from palpate.argtypes import non_negative_int, positive_int
from palpate.calibration import config_lines
from palpate.campaigns.campaign import default_workers, median_abs_relative_error
from palpate.campaigns.executors import add_executor_arguments
from palpate.config import resolve
from palpate.exitcodes import EXIT_FAULT, EXIT_OK
from palpate.live import add_live_argument, live_view
from palpate.progress import progress_bar
from palpate.reports import verdicts
from palpate.reports.campaign_table import print_table
from palpate.services.campaign import Campaign, CampaignDone, CampaignRequest, finish, opened
from palpate.services.campaign import run as run_campaign_service
from palpate.simulation.trial import TrialOutcome
from palpate.simulation.world import tissue_description

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


def request_of(args: argparse.Namespace) -> CampaignRequest:
    """The service's request from the command's options."""
    if args.scene:
        paths: tuple[Path, ...] = (Path(args.scene),)
    else:
        paths = tuple(resolve(f"scenes/{name}.yaml") for name in CAMPAIGNS[args.campaign])
    return CampaignRequest(
        paths,
        seed=args.seed,
        out=args.out,
        workers=args.workers,
        executor=args.executor,
        scheduler=args.scheduler,
        wire=args.wire,
        limit=args.limit,
        resume=args.resume,
        mcap=not args.no_mcap,
        plots=not args.no_plots,
    )


def run(args: argparse.Namespace) -> int:
    """Exit 0 when every trial ended as planned (DONE), 1 when any did not (the tables are
    printed all the same), 2 on bad input (see docs/reliability.md)."""
    if args.faults:
        from palpate.faults import run_command

        return run_command(args)
    request = request_of(args)
    with opened(request) as campaigns:
        with live_view(args.live, campaigns[0].stack) as live:
            request = dataclasses.replace(request, live=live)
            wall_all = _run(campaigns, request)
        if args.compare_methods:
            _compare(campaigns, args)
        elif args.compare_paper:
            _compare_paper(campaigns, args)
        else:
            _print_results([finish(c, request) for c in campaigns], args, wall_all)
    faulted = any(o.state != "done" for c in campaigns for o in c.outcomes)
    return EXIT_FAULT if faulted else EXIT_OK


def _run(campaigns: list[Campaign], request: CampaignRequest) -> float:
    """The service's run, with a progress bar."""
    bar = progress_bar(sum(len(c.to_run()) for c in campaigns), "campaign")
    bar.set_description(" + ".join(c.scene.name for c in campaigns) + " campaign")

    def progress(o: TrialOutcome) -> None:
        bar.update(1)
        bar.set_postfix_str(o.spec.trial_id)

    try:
        return run_campaign_service(campaigns, request, progress)
    finally:
        bar.close()


def _print_results(done: list[CampaignDone], args: argparse.Namespace, wall_all: float) -> None:
    payloads = [d.report.as_dict() for d in done]
    if args.json:
        if len(payloads) == 1:
            print(json.dumps(payloads[0], indent=2))
        else:
            print(json.dumps({"campaigns": payloads, "wall_s": wall_all}, indent=2))
        return
    for d in done:
        _print_report(d, args)
    if len(done) > 1:
        total = sum(len(d.campaign.outcomes) for d in done)
        sim_all = sum(o.sim_time for d in done for o in d.campaign.outcomes)
        print(
            f"all {total} trials in {wall_all:.1f} s wall for {sim_all:.1f} s simulated: "
            f"{sim_all / wall_all:.1f}x real time (one pool for all: each campaign's wall time "
            "above runs from the previous campaign's last trial)"
        )


def _compare(campaigns: list[Campaign], args: argparse.Namespace) -> None:
    from palpate.reports.methods import compare_methods, comparison_payload, print_comparison
    from palpate.robot.trial.setup import sensor_section

    for c in campaigns:
        table = compare_methods(c.outcomes, c.stack, sensor_section(c.stack))
        if args.json:
            print(json.dumps(comparison_payload(table, c.scene.name, args.seed), indent=2))
        else:
            print_comparison(table, c.scene.name)


def _compare_paper(campaigns: list[Campaign], args: argparse.Namespace) -> None:
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


def _print_report(done: CampaignDone, args: argparse.Namespace) -> None:
    """One campaign's table and summary lines, as a person reads them."""
    c, records, found = done.campaign, done.report.samples, done.report.calibration
    files = done.figures + [str(f) for f in done.files]
    scene, outcomes, wall = c.scene, c.outcomes, c.wall
    executor, workers = done.pool
    sim_time = sum(o.sim_time for o in outcomes)
    paper = median_abs_relative_error(outcomes, "paper")
    failed = [o for o in outcomes if o.state != "done"]
    print_table(c.scene.name, records)
    samples = c.scene.campaign_samples()
    tissues = {s.name: tissue_description(scene, c.stack, s.name) for s in samples}
    levels = sorted({t["level"] for t in tissues.values()})
    note = " (the estimator's own model: this judges self-consistency)" * ("closed-form" in levels)
    print(f"world tissue: {', '.join(levels)}{note}")
    for name, tissue in tissues.items():
        stops = tissue.get("table_stops")
        if stops is not None:
            print(
                f"  {name}: the world's finite elements stop at delta/R "
                f"{stops['delta_over_r']:.3g} of the {stops['asked_delta_over_r']:.3g} asked "
                f"({stops['message']}): deeper, its force is the table's extrapolation, not the "
                "FE, and its trials measure the estimator against that extrapolation"
            )
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
        f"{len(outcomes)} trials ({c.transport} path, {executor} executor, "
        f"{workers} worker(s)) in {wall:.1f} s "
        f"wall for {sim_time:.1f} s simulated: {sim_time / wall:.1f}x real time"
    )
    for o in failed:
        print(f"  trial {o.spec.trial_id}: {o.state}: {o.reason}")
    print(f"run folder: {c.run_dir}")
    print(f"logs: {c.log_dir}")
    for f in files:
        print(f"{'plot' if f.endswith('.png') else 'results'}: {f}")
    print()
