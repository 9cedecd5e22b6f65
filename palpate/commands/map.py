"""Map a patch of a simulated sample probe by probe and find the stiff inclusion in it.

Runs a scene's map campaign (``campaign.kind: map``; the shipped one:
``config/scenes/maps/inclusion.yaml``): each probe a whole simulated trial, the next point
chosen by the plan (``--strategy active``: where the boundary is least certain, travel-aware;
``raster`` and ``random`` as baselines), then the Gaussian-process map of the modulus, the
region above the threshold and the inclusion's centre and radius with 95 % intervals, or "no
inclusion found" with the evidence. The run folder (``--out``/<stamp>) keeps the probes
(``probes.jsonl``, appended as they finish), the trial logs, ``map.json`` and ``map.png``;
``--resume`` carries the newest run of the same configuration on from its last probe.
docs/maps.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
from pathlib import Path
from typing import Any, Literal

from palpate.argtypes import float_in, non_negative_int, positive_int
from palpate.campaigns.runs import fingerprint, locked, new_run_dir, resumable, write_run_info
from palpate.campaigns.survey import SurveyResult, run_survey
from palpate.config import InputError, load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.exitcodes import EXIT_OK
from palpate.live import add_live_argument, live_view
from palpate.maps import STRATEGIES, Probe
from palpate.progress import progress_bar
from palpate.reports.mapresults import map_lines, write_map_results

SHIPPED = "scenes/maps/inclusion.yaml"


def register(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--scene", type=Path, help=f"a map scene YAML (default: {SHIPPED})")
    parser.add_argument("--sample", help="survey this sample of the scene instead")
    parser.add_argument("--strategy", choices=STRATEGIES, help="override campaign.strategy")
    parser.add_argument("--max-probes", type=positive_int, help="override campaign.max_probes")
    parser.add_argument("--seed", type=non_negative_int, default=0, help="the run's seed")
    parser.add_argument("--out", type=Path, default=Path("out/map"), help="run folders here")
    parser.add_argument(
        "--resume", action="store_true", help="carry on the newest run of this configuration"
    )
    parser.add_argument("--no-plots", action="store_true", help="skip map.png")
    add_live_argument(parser, "each probe's trial and the map after it")
    parser.add_argument(
        "--through",
        type=parse_through,
        help="how probes reach the patch, overriding campaign.map_through: stage (the x-y "
        "stage moves the sample), robot (a positioner carries the robot); a study takes "
        "stage,robot to survey every world both ways, side by side",
    )
    parser.add_argument(
        "--tilt-deg",
        type=float_in(0.0, 80.0),
        help="override campaign.map_tilt_deg: the patch's plane tilted from facing the robot "
        "(needs --through robot)",
    )
    parser.add_argument(
        "--worlds",
        type=positive_int,
        help="a study instead: this many seeded worlds (the inclusion at a random point of the "
        "patch), each surveyed by every plan of --plans, and as many homogeneous ones",
    )
    parser.add_argument(
        "--plans",
        type=parse_plans,
        default="active:30,raster:25,raster:49,random:30",
        help="the study's plans, strategy:budget, comma-separated",
    )
    parser.add_argument("--workers", type=positive_int, default=2, help="the study's processes")
    parser.add_argument(
        "--whole",
        action="store_true",
        help="the study's worlds drawn whole: 0-3 spheres each, their sizes, contrasts (a "
        "quarter soft) and depths drawn (a scene with fidelity.inclusion_offsets: patch)",
    )


def map_scene(path: Path, sample: str | None) -> SceneConfig:
    """The map scene at ``path`` (with ``sample`` surveyed instead of its campaign's);
    InputError naming the file and key when it is not a map scene."""
    scene = load(SceneConfig, path)
    if scene.campaign.kind != "map":
        raise InputError(
            f"{path}: campaign.kind: palpate map runs kind: map, got {scene.campaign.kind!r}"
        )
    if sample is not None:
        if sample not in [s.name for s in scene.samples]:
            raise InputError(f"--sample: {path} has no sample {sample!r}")
        scene = dataclasses.replace(
            scene, campaign=dataclasses.replace(scene.campaign, samples=(sample,))
        )
    return scene


Way = Literal["stage", "robot"]
WAYS: tuple[Way, ...] = ("stage", "robot")


def parse_through(text: str) -> tuple[Way, ...]:
    """``stage``, ``robot`` or ``stage,robot`` (``--through``' type)."""
    names = [w.strip() for w in text.split(",")]
    ways = tuple(w for w in WAYS if w in names)
    if len(ways) != len(names):
        raise argparse.ArgumentTypeError(f"{text!r} is not stage, robot or stage,robot")
    return ways


def reached(
    scene: SceneConfig, path: Path, through: Way | None, tilt_deg: float | None
) -> SceneConfig:
    """The scene with ``--through`` and ``--tilt-deg`` in its campaign (InputError naming
    the option when the result is not a valid map campaign)."""
    changes: dict[str, Any] = {}
    if through is not None:
        changes["map_through"] = through
    if tilt_deg is not None:
        changes["map_tilt_deg"] = tilt_deg
    if not changes:
        return scene
    try:
        campaign = dataclasses.replace(scene.campaign, **changes)
        moved = dataclasses.replace(scene, campaign=campaign)
        moved.validate()
    except ValueError as exc:
        raise InputError(f"--through/--tilt-deg on {path}: {exc}") from exc
    return moved


def run(args: argparse.Namespace) -> int:
    """Exit 0 when the survey ran (found or not), 2 on bad input."""
    path = Path(args.scene) if args.scene else resolve(SHIPPED)
    ways: tuple[Way, ...] = args.through or ()
    if len(ways) > 1 and not args.worlds:
        raise InputError("--through stage,robot: both ways side by side is a study (--worlds N)")
    scene = map_scene(path, args.sample)
    for way in ways[1:]:
        reached(scene, path, way, args.tilt_deg)  # each way checked before anything runs
    scene = reached(scene, path, ways[0] if ways else None, args.tilt_deg)
    stack = load_stack(resolve(scene.robot))
    info = {
        "scene": scene.name,
        "fingerprint": fingerprint(scene, stack),
        "seed": args.seed,
        "strategy": args.strategy or scene.campaign.strategy,
        "max_probes": args.max_probes or scene.campaign.max_probes,
    }
    if args.worlds:
        return _study(scene, stack, args)
    run_dir = resumable(args.out, info) if args.resume else new_run_dir(args.out)
    with locked(run_dir):
        write_run_info(run_dir, info)
        result = _survey(scene, stack, args, run_dir)
        payload = write_map_results(
            result,
            run_dir,
            info,
            threshold=scene.campaign.map_threshold,
            title=scene.name,
            plots=not args.no_plots,
        )
    if args.json:
        print(json.dumps(payload, indent=2))
    else:
        print("\n".join(map_lines(result, run_dir, scene.name, info["strategy"])))
    return EXIT_OK


def _survey(
    scene: SceneConfig, stack: Any, args: argparse.Namespace, run_dir: Path
) -> SurveyResult:
    bar = progress_bar(args.max_probes or scene.campaign.max_probes, f"{scene.name} map")

    def on_probe(p: Probe) -> None:
        bar.update(1)
        bar.set_postfix_str(f"({p.x * 1e3:+.1f}, {p.y * 1e3:+.1f}) mm {p.status}")

    try:
        with live_view(args.live, stack) as view:
            return run_survey(
                scene,
                stack,
                seed=args.seed,
                strategy=args.strategy,
                max_probes=args.max_probes,
                run_dir=run_dir,
                on_probe=on_probe,
                live=view,
            )
    finally:
        bar.close()


def parse_plans(text: str) -> list[tuple[str, int]]:
    """``active:30,raster:49`` -> [("active", 30), ("raster", 49)] (``--plans``' type: a bad
    item is argparse's error naming the option)."""
    plans = []
    for item in text.split(","):
        name, _, budget = item.strip().partition(":")
        if name not in STRATEGIES or not budget.isdigit() or int(budget) < 1:
            raise argparse.ArgumentTypeError(
                f"{item!r} is not strategy:budget, budget >= 1 ({', '.join(STRATEGIES)})"
            )
        plans.append((name, int(budget)))
    return plans


def _study(scene: SceneConfig, stack: Any, args: argparse.Namespace) -> int:
    from palpate.campaigns.mapstudy import run_map_study, summarise_study

    plans: list[tuple[str, int]] = args.plans
    whole = args.whole
    if whole and scene.fidelity.inclusion_offsets != "patch":
        raise InputError(
            f"--whole: worlds drawn whole need fidelity.inclusion_offsets: patch (the scene has "
            f"{scene.fidelity.inclusion_offsets!r}; config/scenes/maps/several.yaml has it)"
        )
    extra = any(p[0] == "active" for p in plans) and not whole
    total = args.worlds * (len(plans) + extra) * len(args.through or (None,))
    bar = progress_bar(total, f"{scene.name} map study")

    def done(_: dict[str, Any]) -> None:
        bar.update(1)

    try:
        rows = run_map_study(
            scene,
            stack,
            worlds=args.worlds,
            plans=plans,
            seed=args.seed,
            workers=args.workers,
            progress=done,
            whole=whole,
            throughs=args.through or (scene.campaign.map_through,),
        )
    finally:
        bar.close()
    table = summarise_study(rows)
    run_dir = new_run_dir(args.out)
    payload = {
        "scene": scene.name,
        "worlds": args.worlds,
        "whole": whole,
        "seed": args.seed,
        "summary": table,
        "rows": rows,
        "run_dir": str(run_dir),
    }
    (run_dir / "study.json").write_text(json.dumps(payload, indent=2) + "\n", encoding="utf-8")
    if args.json:
        print(json.dumps(payload, indent=2))
    else:
        for line in table:
            print(json.dumps(line))
        print(f"study: {run_dir / 'study.json'}")
    return EXIT_OK
