"""Run scripted indentation trials on the real bench: ports, stored poses and protocol from a YAML.

``palpate trial --config config/bench.yaml [--target NAME] [--dry-run]``. The trials run through
the same state machine and trial loop as ``palpate sim``, with dynamixel-sdk on the servo port and
pyserial on the board port; each writes its log as it goes. ``--dry-run`` checks the file, the
targets and the limits and shows the plan without opening a port.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from palpate.calibration import config_lines
from palpate.config.bench import LoadedBench, load_bench
from palpate.estimation.verdict import STATUSES
from palpate.lab.hardware import port_problem, run_on_hardware
from palpate.lab.plan import describe_map, plan_session
from palpate.lab.trial import SKIPPED, BenchOutcome, BenchTrial
from palpate.live import add_live_argument
from palpate.reports.results import CampaignResults
from palpate.services.lab import SessionResults, run_map_session, session_results, with_ports

if TYPE_CHECKING:  # the maps import scikit-learn: only when a bench file maps
    from palpate.campaigns.surveyloop import SurveyResult


def register(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--config",
        default="bench.yaml",
        help="the bench file: a path, or a name in the shipped config/",
    )
    parser.add_argument("--target", help="run only the trials at this stored pose")
    parser.add_argument(
        "--dry-run", action="store_true", help="check and show the plan; open no port"
    )
    parser.add_argument("--log-dir", type=Path, help="overrides log_dir of the bench file")
    add_live_argument(parser, "each trial")
    parser.add_argument(
        "--servo-port", help="overrides servos.port of the bench file (e.g. an emulator's pty)"
    )
    parser.add_argument("--board-port", help="overrides board.port of the bench file")


def run(args: argparse.Namespace) -> int:
    loaded = with_ports(load_bench(args.config), args.servo_port, args.board_port)
    trials, survey = plan_session(loaded, args.target)
    if args.dry_run:
        return _dry_run(loaded, trials, args.json, survey)
    base = args.log_dir if args.log_dir is not None else Path(loaded.bench.log_dir)
    log_dir = base / time.strftime("%Y%m%d-%H%M%S")
    quiet = args.json

    results = CampaignResults(log_dir)

    def progress(o: BenchOutcome) -> None:
        results.add(o.as_dict())  # each trial's row on disk as it finishes
        if not quiet:
            print(_row(o.as_dict()), flush=True)

    if not quiet:
        then = f", then {describe_map(loaded, survey)}" if survey is not None else ""
        print(f"{len(trials)} trial(s) from {loaded.path}{then}; logs in {log_dir}")
        print(_HEAD)
    outcomes: list[BenchOutcome] = []
    surveyed: list[SurveyResult | None] = [None]

    def body() -> int:
        done, surveyed[0] = run_map_session(
            loaded, trials, survey, log_dir, progress=progress, live=args.live
        )
        outcomes.extend(done)
        return 0

    code = run_on_hardware("trial", body)
    if code:
        return code
    return _report(args, loaded, session_results(loaded, log_dir, outcomes, surveyed[0], results))


def _report(args: argparse.Namespace, loaded: LoadedBench, done: SessionResults) -> int:
    """The session's results (files written by the service, then stdout); exit 0 when every
    trial and probe is done."""
    if args.json:
        print(json.dumps(done.payload, indent=2))
    else:
        robot = loaded.bench.robot
        _print_summary(done.outcomes, done.samples, done.calibration, robot, done.files)
        if done.mapped is not None:
            from palpate.reports.mapresults import map_lines

            m = loaded.bench.map
            assert m is not None
            lines = map_lines(done.mapped, done.log_dir, f"map at {m.target}", m.strategy)
            print("\n".join(lines))
    return 0 if all(o.state == "done" for o in done.outcomes) else 1


def _print_summary(
    outcomes: list[BenchOutcome],
    samples: list[dict[str, Any]],
    found: dict[str, tuple[float, float]],
    robot: str,
    files: list[Path],
) -> None:
    """The session's end as a person reads it: skipped trials, the calibration, each sample's
    statistics and the results files."""
    for o in outcomes:
        if o.state == SKIPPED:
            print(_row(o.as_dict()))
    for line in config_lines(found):
        print(f"calibrated on the rigid reference (store in {robot}): {line}")
    for s in samples:
        if s["reference_kpa"] is None:
            print(
                f"sample {s['sample']} (modulus not given): joint fit mean "
                f"{_kpa(s['joint_mean_kpa'])} kPa over {s['count']} ok trials; verdicts "
                + ", ".join(f"{s[v]} {v}" for v in STATUSES)
            )
            _print_pooled(s)
            continue
        rel = s["joint_relative_error"]
        print(
            f"sample {s['sample']}: joint fit mean {_kpa(s['joint_mean_kpa'])} kPa vs "
            f"{s['reference_kpa']:.2f} kPa, RMSE {_kpa(s['joint_rmse_kpa'])}, IQR "
            f"{_kpa(s['joint_iqr_kpa'])}, relative error "
            + ("-" if rel is None else f"{100 * rel:+.1f} %")
            + f" ({s['count']} ok kept, {s['outliers']} outliers; verdicts "
            + ", ".join(f"{s[v]} {v}" for v in STATUSES)
            + f"); the paper's estimate's mean {_kpa(s['paper_mean_kpa'])} kPa"
        )
        _print_pooled(s)
    for f in files:
        print(f"results: {f}")


def _print_pooled(s: dict[str, Any]) -> None:
    """The sample's trials pooled, under its line."""
    if s["pooled_kpa"] is None:
        return
    why = f": {s['pooled_reasons']}" if s["pooled_reasons"] else ""
    what = "relaxed modulus " if s.get("pooled_modulus") == "relaxed" else ""
    print(
        f"  pooled over {s['pooled_trials']} trials: {what}{s['pooled_kpa']:.2f} "
        f"[{s['pooled_ci_low_kpa']:.2f}, {s['pooled_ci_high_kpa']:.2f}] kPa, "
        f"{s['pooled_verdict']}{why}"
    )


def _dry_run(
    loaded: LoadedBench, trials: list[BenchTrial], as_json: bool, survey: BenchTrial | None
) -> int:
    stack, m = loaded.stack, loaded.bench.map
    ports = {
        "servos": (stack.servos.port, port_problem(stack.servos.port, "servo bus", "servos.port")),
        "board": (
            stack.board.port,
            port_problem(stack.board.port, "acquisition board", "board.port"),
        ),
    }
    if as_json:
        payload = {
            "bench": str(loaded.path),
            "targets": str(loaded.targets_path),
            "ports": {k: {"port": p, "problem": why} for k, (p, why) in ports.items()},
            "trials": [t.describe() for t in trials],
            "map": None
            if m is None or survey is None
            else {**dataclasses.asdict(m), **survey.describe()},
        }
        print(json.dumps(payload, indent=2))
        return 0
    print(f"bench file {loaded.path}, targets {loaded.targets_path}: {len(trials)} trial(s)")
    for name, (port, why) in ports.items():  # a problem names its port itself
        print(f"  {name}: {why}" if why else f"  {name} port {port}: present")
    for t in trials:
        d = t.describe()
        print(
            f"  {d['trial']}: tube {d['tube']}, roll {d['roll_deg']:.1f} deg, stand-off "
            f"{d['standoff_translation_mm']:.3f} mm, contact expected at "
            f"{d['contact_translation_mm']:.3f} mm (exposed {d['exposed_length_mm']:.2f} mm), "
            f"retract to {d['retract_translation_mm']:.3f} mm"
        )
    if survey is not None:
        print(f"  then {describe_map(loaded, survey)}")
    print("dry run: no port opened, nothing moved")
    return 0


_HEAD = (
    f"{'trial':<28} {'state':<9} {'joint fit kPa [95 % interval]':>30} {'verdict':<8} "
    f"{'paper kPa':>9} {'reference':>9} {'rel.err':>8}  reason"
)


def _kpa(v: float | None) -> str:
    return "-" if v is None else f"{v:.2f}"


def _relaxed(d: dict[str, Any]) -> list[str]:
    """The relaxed modulus of a trial that held, for its line (none otherwise)."""
    if d.get("relaxed_kpa") is None:
        return []
    lo, hi = d["relaxed_ci_kpa"]
    return [
        f"relaxed {_kpa(d['relaxed_kpa'])} [{_kpa(lo)}, {_kpa(hi)}] kPa: {d['relaxed_verdict']}"
    ]


def _row(d: dict[str, Any]) -> str:
    """One trial's line: the joint fit with its interval and verdict, the paper's estimate
    (Eqs. 13-14) beside it, the reference modulus and the joint fit's relative error."""
    rel = "-" if d["relative_error"] is None else f"{100 * d['relative_error']:+.1f}%"
    joint = _kpa(d["joint_kpa"])
    if d["joint_ci_kpa"] is not None:
        lo, hi = d["joint_ci_kpa"]
        joint += f" [{_kpa(lo)}, {_kpa(hi)}]"
    verdict = d["verdict"] or "-"
    why = "; ".join([d["reason"], *d["verdict_reasons"], *_relaxed(d)])
    cal = d.get("calibration")
    if cal is not None:
        c = cal.get("compliance")
        joint = "-" if c is None else f"c = {1e3 * c:.4g} mm/N"
        verdict = "calib."
    return (
        f"{d['trial']:<28} {d['state']:<9} {joint:>30} {verdict:<8} "
        f"{_kpa(d['paper_kpa']):>9} {_kpa(d['reference_kpa']):>9} {rel:>8}  {why}"
    )
