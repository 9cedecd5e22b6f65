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
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from palpate.calibration import calibrate, config_lines
from palpate.commands.benchsamples import bench_samples
from palpate.config.bench import LoadedBench, load_bench
from palpate.estimation.verdict import STATUSES
from palpate.lab.hardware import open_hardware, port_problem, run_on_hardware
from palpate.lab.plan import describe_map, plan_session
from palpate.lab.trial import (
    SKIPPED,
    BenchOutcome,
    BenchTrial,
    Session,
    run_bench_trials,
)
from palpate.live import add_live_argument, live_view
from palpate.reports.results import CampaignResults
from palpate.sensor.clock import Clock
from palpate.sensor.reader import SerialLike

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


def run_session(
    loaded: LoadedBench, trials: list[BenchTrial], log_dir: Path, **options: Any
) -> list[BenchOutcome]:
    """Open the bench (ports from the file unless given) and run ``trials``; torque is off and
    the ports closed on return, whatever happened: :func:`run_map_session` without a map
    (``options``: its keywords). Tests pass the emulators' ptys and a virtual clock (with
    ``sync_to_clock``)."""
    outcomes, _ = run_map_session(loaded, trials, None, log_dir, **options)
    return outcomes


def run_map_session(
    loaded: LoadedBench,
    trials: list[BenchTrial],
    survey: BenchTrial | None,
    log_dir: Path,
    *,
    servo_port: str | Any | None = None,
    board_port: str | SerialLike | None = None,
    clock: Clock | None = None,
    sync_to_clock: bool = False,
    progress: Callable[[BenchOutcome], None] | None = None,
    live: int | None = None,
) -> tuple[list[BenchOutcome], SurveyResult | None]:
    """Open the bench (ports from the file unless given: the emulators' ptys in tests, with a
    virtual clock and ``sync_to_clock``; ``live``: the live view's port, ``--live``), run
    ``trials``, then, with a ``survey`` (the trial each probe repeats,
    ``palpate.commands.benchmap.plan_bench_map``), the bench file's map on the x-y stage with the
    compliance the trials calibrated: the trials' outcomes and the map (None without one, or
    when a trial before it ended the session)."""
    key = str(loaded.path)
    with (
        open_hardware(
            loaded.stack,
            servo_port=servo_port,
            board_port=board_port,
            clock=clock,
            servo_key=f"servos.port in {key}",
            board_key=f"board.port in {key}",
        ) as hw,
        live_view(live, loaded.stack) as view,
    ):
        session = Session(loaded.stack)
        outcomes = run_bench_trials(
            hw,
            trials,
            loaded,
            log_dir,
            sync_to_clock=sync_to_clock,
            progress=progress,
            live=view,
            session=session,
        )
        if survey is None or any(o.state == SKIPPED for o in outcomes):
            return outcomes, None
        from palpate.commands.benchmap import run_bench_map

        result = run_bench_map(
            hw,
            survey,
            loaded,
            session.stack,
            log_dir,
            sync_to_clock=sync_to_clock,
            progress=progress,
            live=view,
        )
        return outcomes, result


def _with_ports(loaded: LoadedBench, servo: str | None, board: str | None) -> LoadedBench:
    """``loaded`` with the servo and board ports replaced where given."""
    stack = loaded.stack
    if servo is not None:
        stack = dataclasses.replace(stack, servos=dataclasses.replace(stack.servos, port=servo))
    if board is not None:
        stack = dataclasses.replace(stack, board=dataclasses.replace(stack.board, port=board))
    return dataclasses.replace(loaded, stack=stack)


def run(args: argparse.Namespace) -> int:
    loaded = _with_ports(load_bench(args.config), args.servo_port, args.board_port)
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
    return code or _report(args, loaded, log_dir, outcomes, surveyed[0], results)


def _report(
    args: argparse.Namespace,
    loaded: LoadedBench,
    log_dir: Path,
    outcomes: list[BenchOutcome],
    mapped: SurveyResult | None,
    results: CampaignResults,
) -> int:
    """The session's results (files, then stdout); exit 0 when every trial and probe is done."""
    samples = bench_samples(outcomes, loaded.bench.campaign.outlier_above)  # the trials, not probes
    found = calibrate(
        (o.trial.stage.rig_key, o.calibration) for o in outcomes if o.calibration is not None
    )
    probes = [] if mapped is None else [o for o in mapped.outcomes if o is not None]
    outcomes = outcomes + probes  # every trial's row; the samples' statistics leave probes out
    trial_rows = [o.as_dict() for o in outcomes]
    payload: dict[str, Any] = {
        "bench": str(loaded.path),
        "log_dir": str(log_dir),
        "trials": trial_rows,
        "samples": samples,
        "calibration": {k: [lo * 1e3, hi * 1e3] for k, (lo, hi) in found.items()},
    }
    if mapped is not None:
        payload["map"] = _map_results(mapped, loaded, log_dir)
    files = results.finish(trial_rows, samples, payload) if outcomes else []
    if args.json:
        print(json.dumps(payload, indent=2))
    else:
        _print_summary(outcomes, samples, found, loaded.bench.robot, files)
        if mapped is not None:
            from palpate.reports.mapresults import map_lines

            m = loaded.bench.map
            assert m is not None
            print("\n".join(map_lines(mapped, log_dir, f"map at {m.target}", m.strategy)))
    return 0 if all(o.state == "done" for o in outcomes) else 1


def _map_results(mapped: SurveyResult, loaded: LoadedBench, log_dir: Path) -> dict[str, Any]:
    """The map's files in the session folder (``map.json``, ``.mcap``, ``.png``); its payload."""
    from palpate.reports.mapresults import write_map_results

    m = loaded.bench.map
    assert m is not None
    info = {"target": m.target, "strategy": m.strategy, "max_probes": m.max_probes}
    return write_map_results(
        mapped, log_dir, info, threshold=m.threshold, title=f"map at {m.target}", plots=True
    )


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
