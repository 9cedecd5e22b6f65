"""Design a sensor for a tissue modulus range, then try it on simulated phantoms across the range.

``palpate design --modulus-range 1:10 --unit kPa`` proposes the fiber, wires, tip radius and
exposed length (``estimation.design``), prints the predicted indentation at buckling at both
ends of the range with every check's margin, then runs a short simulated bench campaign with
the proposed sensor on phantoms spread over the range (``--no-sim`` skips it). Exit code 2 when
no design satisfies the constraints (the message names the failing constraint).
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import Any

from config import load, load_stack, resolve
from config.scene import SceneConfig
from config.schema import StackConfig
from estimation.design import (
    DesignConstraints,
    DesignEvaluation,
    DesignResult,
    DesignSpace,
    design_sensor,
)
from palpate.argtypes import non_negative_int, positive_int
from palpate.campaigns.campaign import campaign_trials, default_workers
from palpate.campaigns.designcheck import (
    METHODS,
    UNITS,
    CheckSettings,
    design_scene,
    error_summary,
    relative_error,
    run_check,
)
from palpate.campaigns.executors import add_executor_arguments
from palpate.progress import progress_bar
from palpate.simulation.trial import TrialOutcome
from sensor.strain import strain_noise
from wire.dynamixel import TICKS_PER_REV

EXIT_NO_DESIGN = 2


def _floats(text: str, what: str) -> tuple[float, ...]:
    try:
        values = tuple(float(v) for v in text.split(",") if v.strip())
    except ValueError:
        raise ValueError(f"{what}: expected comma-separated numbers, got {text!r}") from None
    if not values:
        raise ValueError(f"{what}: empty list")
    return values


def _pair(text: str, what: str) -> tuple[float, float]:
    parts = text.split(":")
    try:
        lo, hi = (float(p) for p in parts)
    except ValueError:
        raise ValueError(f"{what}: expected MIN:MAX, got {text!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo <= hi):
        raise ValueError(f"{what}: need 0 < MIN <= MAX, got {text!r}")
    return lo, hi


def register(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--modulus-range", required=True, metavar="MIN:MAX", help="tissue moduli, e.g. 1:10"
    )
    parser.add_argument("--unit", choices=sorted(UNITS), default="kPa", help="of --modulus-range")
    parser.add_argument("--poisson", type=float, default=0.45, help="tissue Poisson ratio")
    parser.add_argument(
        "--thickness-mm", type=float, default=20.0, help="tissue layer thickness (inf: half-space)"
    )
    parser.add_argument(
        "--imperfection",
        type=float,
        default=5e-4,
        help="initial bow w0/L of the sensor (also used by the simulated campaign)",
    )
    parser.add_argument(
        "--resolution-multiple",
        type=float,
        default=20.0,
        help="smallest indentation at buckling, in encoder counts",
    )
    space = DesignSpace()
    for flag, values, what in (
        ("--fiber-radii-um", [f"{r * 1e6:g}" for r in space.fiber_radii], "fiber radii"),
        ("--wire-diameters-um", [f"{d * 1e6:g}" for d in space.wire_diameters], "wire diameters"),
        ("--wire-counts", [str(n) for n in space.wire_counts], "numbers of NiTi wires"),
        ("--tip-radii-mm", [f"{r * 1e3:g}" for r in space.tip_radii], "tip sphere radii"),
    ):
        parser.add_argument(
            flag, default=",".join(values), help=f"{what} to consider (comma-separated)"
        )
    parser.add_argument(
        "--length-range-mm",
        default=":".join(f"{v * 1e3:g}" for v in space.length_range),
        metavar="MIN:MAX",
        help="exposed lengths to consider",
    )
    parser.add_argument("--config", default="robot.yaml", help="robot/sensor YAML (fiber, drive)")
    parser.add_argument(
        "--scene", type=Path, help="scene YAML whose fidelity and campaign settings the check uses"
    )
    parser.add_argument("--moduli", type=positive_int, default=4, help="phantoms across the range")
    parser.add_argument(
        "--lengths", type=positive_int, default=2, help="exposed lengths per phantom"
    )
    parser.add_argument(
        "--contact-uncertainty-mm",
        type=float,
        default=0.0,
        help="contact-detection error (1 sigma) in the simulated campaign",
    )
    parser.add_argument(
        "--seed", type=non_negative_int, default=0, help="makes the simulated check reproducible"
    )
    parser.add_argument(
        "--workers",
        type=positive_int,
        default=default_workers(),
        help="trials of the check run in parallel (processes, threads or local Dask workers)",
    )
    add_executor_arguments(parser)
    parser.add_argument("--no-sim", action="store_true", help="skip the simulated campaign")


def _inputs(
    args: argparse.Namespace, stack: StackConfig, scene: SceneConfig
) -> tuple[tuple[float, float], DesignConstraints, DesignSpace]:
    unit = UNITS[args.unit]
    lo, hi = _pair(args.modulus_range, "--modulus-range")
    thickness = None if math.isinf(args.thickness_mm) else args.thickness_mm * 1e-3
    s = stack.sensor
    constraints = DesignConstraints(
        poisson=args.poisson,
        thickness=thickness,
        encoder_resolution=stack.drive.lead / TICKS_PER_REV,
        resolution_multiple=args.resolution_multiple,
        strain_limit=stack.fbg.strain_limit,
        strain_noise=strain_noise(
            scene.fidelity.fbg_noise_pm, stack.fbg.strain_coefficient_pm_per_ue
        ),
        imperfection=args.imperfection,
        post_buckling_travel=scene.campaign.post_buckling_mm * 1e-3,
        grating_centres_from_tip=s.grating_centres_from_tip(),
        grating_length=s.grating_length,
    )
    lengths = _pair(args.length_range_mm, "--length-range-mm")
    space = DesignSpace(
        fiber_radii=tuple(r * 1e-6 for r in _floats(args.fiber_radii_um, "--fiber-radii-um")),
        fiber_modulus=s.fiber_modulus,
        wire_modulus=s.wire_modulus,
        wire_diameters=tuple(
            d * 1e-6 for d in _floats(args.wire_diameters_um, "--wire-diameters-um")
        ),
        wire_counts=tuple(int(n) for n in _floats(args.wire_counts, "--wire-counts")),
        tip_radii=tuple(r * 1e-3 for r in _floats(args.tip_radii_mm, "--tip-radii-mm")),
        length_range=(lengths[0] * 1e-3, lengths[1] * 1e-3),
    )
    return (lo * unit, hi * unit), constraints, space


def _settings(args: argparse.Namespace) -> CheckSettings:
    return CheckSettings(
        unit=args.unit,
        moduli=args.moduli,
        lengths=args.lengths,
        poisson=args.poisson,
        thickness_mm=args.thickness_mm,
        imperfection=args.imperfection,
        contact_uncertainty_mm=args.contact_uncertainty_mm,
    )


def _run_sim(
    scene: SceneConfig, stack: StackConfig, args: argparse.Namespace
) -> tuple[list[TrialOutcome], float]:
    specs = campaign_trials(scene, stack, args.seed)
    bar = progress_bar(len(specs), "design check")

    def progress(o: TrialOutcome) -> None:
        bar.update(1)
        bar.set_postfix_str(o.spec.trial_id)

    outcomes, wall = run_check(
        specs,
        scene,
        stack,
        executor=args.executor,
        workers=args.workers,
        scheduler=args.scheduler,
        progress=progress,
    )
    bar.close()
    return outcomes, wall


def run(args: argparse.Namespace) -> int:
    stack = load_stack(args.config)
    scene_path = args.scene if args.scene else resolve("scenes/bench.yaml")
    base = load(SceneConfig, scene_path)
    if args.moduli < 1 or args.lengths < 1:
        raise ValueError("--moduli and --lengths must be >= 1")
    if args.contact_uncertainty_mm < 0:
        raise ValueError("--contact-uncertainty-mm must be >= 0")
    modulus_range, constraints, space = _inputs(args, stack, base)
    result = design_sensor(modulus_range, constraints, space)
    outcomes: list[TrialOutcome] = []
    wall = 0.0
    if result.success and not args.no_sim:
        assert result.evaluation is not None
        assert result.length_window is not None
        scene, sim_stack = design_scene(
            result.evaluation, result.length_window, stack, base, _settings(args)
        )
        outcomes, wall = _run_sim(scene, sim_stack, args)
    if args.json:
        print(json.dumps(_payload(result, constraints, args, outcomes, wall), indent=2))
    else:
        _print(result, constraints, args, outcomes, wall)
    if not result.success:
        return EXIT_NO_DESIGN
    if any(o.state != "done" for o in outcomes):  # a trial of the check faulted
        return 1
    return 0


# -- output --------------------------------------------------------------------------------------


def _design_dict(result: DesignResult, args: argparse.Namespace) -> dict[str, Any] | None:
    ev = result.evaluation
    if ev is None:
        return None
    d = ev.design
    unit = UNITS[args.unit]
    return {
        "fiber_radius_um": d.fiber_radius * 1e6,
        "wire_count": d.wire_count,
        "wire_diameter_um": d.wire_radius * 2e6,
        "tip_radius_mm": d.tip_radius * 1e3,
        "exposed_length_mm": d.exposed_length * 1e3,
        "length_window_mm": (
            None if result.length_window is None else [v * 1e3 for v in result.length_window]
        ),
        "critical_load_mn": ev.critical_load * 1e3,
        f"modulus_range_{args.unit.lower()}": [e / unit for e in ev.modulus_range],
        "delta_at_min_modulus_mm": ev.delta_soft * 1e3,
        "delta_at_max_modulus_mm": ev.delta_stiff * 1e3,
        "depth_ratio_at_min_modulus": ev.depth_ratio,
        "contact_ratio_at_min_modulus": None if math.isnan(ev.contact_ratio) else ev.contact_ratio,
        "delta_bias_um": ev.delta_bias * 1e6,
        "detector_threshold_ue": None if ev.threshold is None else ev.threshold * 1e6,
        "peak_fiber_strain_ue": ev.peak_strain * 1e6,
        "checks": [
            {
                "name": c.name,
                "description": c.description,
                "value": c.value,
                "limit": c.limit,
                "margin": c.margin,
                "ok": c.ok,
            }
            for c in ev.checks
        ],
    }


def _payload(
    result: DesignResult,
    constraints: DesignConstraints,
    args: argparse.Namespace,
    outcomes: list[TrialOutcome],
    wall: float,
) -> dict[str, Any]:
    return {
        "success": result.success,
        "message": result.message,
        "candidates": result.candidates,
        "feasible": result.feasible,
        "failures": result.failures,
        "encoder_resolution_um": constraints.encoder_resolution * 1e6,
        "design": _design_dict(result, args),
        "campaign": None
        if not outcomes
        else {
            "executor": args.executor,
            "trials": [
                {
                    **o.as_dict(),
                    **{f"relative_error_{m}": relative_error(o, m) for m in METHODS},
                }
                for o in outcomes
            ],
            **{m: error_summary(outcomes, m) for m in METHODS},
            "wall_s": wall,
        },
    }


def _print(
    result: DesignResult,
    constraints: DesignConstraints,
    args: argparse.Namespace,
    outcomes: list[TrialOutcome],
    wall: float,
) -> None:
    print(("design: " if result.success else "NO DESIGN: ") + result.message)
    ev = result.evaluation
    if ev is None:
        return
    print()
    for k, v in _design_rows(result, ev, constraints, args.unit):
        print(f"  {k:<20} {v}")
    print()
    print(f"  {'check':<13} {'value':>10} {'limit':>10} {'margin':>7}  ok")
    for c in ev.checks:
        print(
            f"  {c.name:<13} {c.value:>10.4g} {c.limit:>10.4g} {c.margin:>7.2f}  "
            f"{'yes' if c.ok else 'NO'}"
        )
    if outcomes:
        print()
        _print_campaign(outcomes, args, wall)


def _design_rows(
    result: DesignResult, ev: DesignEvaluation, constraints: DesignConstraints, unit_name: str
) -> list[tuple[str, str]]:
    """(label, value) of the proposed sensor and its predicted indentations."""
    unit = UNITS[unit_name]
    d = ev.design
    lo, hi = ev.modulus_range
    counts = ev.delta_stiff / constraints.encoder_resolution
    wires = (
        "none (bare fiber)" if d.wire_count == 0 else f"{d.wire_count} x {d.wire_radius * 2e6:g} um"
    )
    window = (
        "fails: see the checks"
        if result.length_window is None
        else "all checks pass for "
        f"{result.length_window[0] * 1e3:.1f}-{result.length_window[1] * 1e3:.1f} mm"
    )
    return [
        ("fiber radius", f"{d.fiber_radius * 1e6:g} um"),
        ("NiTi wires", wires),
        ("tip radius", f"{d.tip_radius * 1e3:g} mm"),
        ("exposed length", f"{d.exposed_length * 1e3:.1f} mm ({window})"),
        ("P_cr", f"{ev.critical_load * 1e3:.3g} mN"),
        (
            f"delta at {lo / unit:g} {unit_name}",
            f"{ev.delta_soft * 1e3:.3f} mm (delta/R {ev.depth_ratio:.3f}, a/h "
            f"{ev.contact_ratio:.3f})",
        ),
        (
            f"delta at {hi / unit:g} {unit_name}",
            f"{ev.delta_stiff * 1e3:.3f} mm ({counts:.0f} counts)",
        ),
        ("delta bias", f"{ev.delta_bias * 1e6:.1f} um (compression, detection, bow)"),
        (
            "detector threshold",
            "-" if ev.threshold is None else f"{ev.threshold * 1e6:.1f} ue (strain norm)",
        ),
    ]


def _print_campaign(outcomes: list[TrialOutcome], args: argparse.Namespace, wall: float) -> None:
    unit = UNITS[args.unit]
    print(f"simulated bench campaign with the proposed sensor ({args.executor} executor):")
    head = f"  {'trial':<34} {'actual':>8}"
    for m in METHODS:
        head += f" {m:>8} {'rel.err':>8}"
    print(head + "  state")
    for o in outcomes:
        line = f"  {o.spec.trial_id:<34} {o.spec.modulus / unit:>8.3f}"
        for m in METHODS:
            value, err = o.modulus(m), relative_error(o, m)
            line += " " + ("-" if value is None else f"{value / unit:.3f}").rjust(8)
            line += " " + ("-" if err is None else f"{100 * err:+.1f}%").rjust(8)
        print(f"{line}  {o.state}{'' if o.state == 'done' else ': ' + o.reason}")
    for m in METHODS:
        summary = error_summary(outcomes, m)
        mare, worst = summary["median_abs_relative_error"], summary["max_abs_relative_error"]
        if mare is not None and worst is not None:
            print(f"  {m}: median |relative error| {100 * mare:.1f} %, worst {100 * worst:.1f} %")
    print(f"  {len(outcomes)} trials in {wall:.1f} s wall; moduli in {args.unit}")
