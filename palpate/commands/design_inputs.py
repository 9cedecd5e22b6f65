"""``palpate design``'s arguments and what they make: the tissue's constraints, the design
space (a lumen's, with ``--lumen-mm``), the search and the tip grating."""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

from palpate.argtypes import (
    float_in,
    non_negative_float,
    non_negative_int,
    number_list,
    number_range,
    positive_float,
    positive_int,
    positive_or_inf,
)
from palpate.campaigns.campaign import default_workers
from palpate.campaigns.designcheck import DEFAULT_TOLERANCE, UNITS
from palpate.campaigns.executors import add_executor_arguments
from palpate.config.loader import InputError
from palpate.config.optics import MM
from palpate.config.scene import SceneConfig
from palpate.config.schema import StackConfig
from palpate.estimation.design import (
    DesignConstraints,
    DesignResult,
    DesignSpace,
    design_sensor,
)
from palpate.estimation.design.lumen import LAW_DEPTH_RATIO, Lumen, span_range
from palpate.estimation.design.tipgrating import (
    TipGratingChoice,
    choose_tip_grating,
    tip_grating_for_resolution,
)
from palpate.reports.lumen import LumenReport
from palpate.sensor.strain import strain_noise
from palpate.wire.dynamixel import TICKS_PER_REV


def register(parser: argparse.ArgumentParser) -> None:
    _add_tissue_arguments(parser)
    _add_space_arguments(parser)
    _add_check_arguments(parser)


def _add_tissue_arguments(parser: argparse.ArgumentParser) -> None:
    """The tissue to design for and what the design must resolve."""
    parser.add_argument(
        "--modulus-range",
        type=number_range(positive_float),
        required=True,
        metavar="MIN:MAX",
        help="tissue moduli, e.g. 1:10",
    )
    parser.add_argument("--unit", choices=sorted(UNITS), default="kPa", help="of --modulus-range")
    parser.add_argument(
        "--poisson", type=float_in(0.0, 0.5), default=0.45, help="tissue Poisson ratio"
    )
    parser.add_argument(
        "--thickness-mm",
        type=positive_or_inf,
        default=20.0,
        help="tissue layer thickness (inf: half-space)",
    )
    parser.add_argument(
        "--imperfection",
        type=float_in(0.0, 0.1, high_open=True),
        default=5e-4,
        help="initial bow w0/L of the sensor (also used by the simulated campaign)",
    )
    parser.add_argument(
        "--max-depth-ratio",
        type=float_in(0.0, LAW_DEPTH_RATIO, low_open=True),
        default=None,
        help="the deepest delta/R at E_min the estimate may rely on (default 0.5, where the "
        "law's finite-strain bound reaches 5 %%; with --lumen-mm 1, the end of its tables: the "
        "bound, 10 %%, is in the intervals)",
    )
    parser.add_argument(
        "--resolution-multiple",
        type=positive_float,
        default=20.0,
        help="smallest indentation at buckling, in encoder counts",
    )


def _candidate_lists(space: DesignSpace) -> list[tuple[str, list[float], Any, str]]:
    """The search's candidate lists as options: flag, default values (the option's unit), the
    type of an item, what they are."""
    return [
        ("--fiber-radii-um", [r * 1e6 for r in space.fiber_radii], positive_float, "fiber radii"),
        ("--wire-diameters-um", [d * 1e6 for d in space.wire_diameters], positive_float,
         "wire diameters"),
        ("--wire-counts", list(space.wire_counts), non_negative_int, "numbers of NiTi wires"),
        ("--tip-radii-mm", [r * 1e3 for r in space.tip_radii], positive_float, "tip sphere radii"),
    ]  # fmt: skip


def _add_space_arguments(parser: argparse.ArgumentParser) -> None:
    """The candidates the search considers."""
    space = DesignSpace()
    for flag, values, kind, what in _candidate_lists(space):
        parser.add_argument(
            flag,
            type=number_list(kind),
            default=",".join(f"{v:g}" for v in values),
            help=f"{what} to consider (comma-separated)",
        )
    parser.add_argument(
        "--lumen-mm",
        type=positive_float,
        default=None,
        help="the working channel the whole sensor must pass (e.g. 2.8): tip, wires and fiber, "
        "the tip grating's element; implies --tip-grating with --tip-resolution-mn; reports the "
        "widest range one sensor spans through it and the second sensor's",
    )
    parser.add_argument(
        "--pose",
        choices=("any", "vertical"),
        default="vertical",
        help="any: the design must carry its own weight held across (the search's weight check, "
        "a solid printed tip sphere; in the body the sensor meets tissue at any angle to "
        "gravity); vertical: the sag is only reported after the search",
    )
    parser.add_argument(
        "--clearance-mm",
        type=non_negative_float,
        default=0.2,
        help="what a tool leaves of the channel",
    )
    parser.add_argument(
        "--tip-resolution-mn",
        type=positive_float,
        default=0.05,
        help="with --lumen-mm, the tip grating's load resolution, 1 sigma (published: 0.25, "
        "0.13, about 0.05 mN)",
    )
    parser.add_argument(
        "--length-range-mm",
        type=number_range(positive_float),
        default=":".join(f"{v * 1e3:g}" for v in space.length_range),
        metavar="MIN:MAX",
        help="exposed lengths to consider",
    )


def _add_check_arguments(parser: argparse.ArgumentParser) -> None:
    """The robot the design is for and the simulated check of the chosen design."""
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
        type=non_negative_float,
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
    parser.add_argument(
        "--tolerance-pct",
        type=float_in(0.0, 100.0, low_open=True),
        default=100 * DEFAULT_TOLERANCE,
        help="the largest |relative error| of the joint fit on a phantom of the simulated check "
        "for the design to be usable (default %(default)g %%)",
    )
    parser.add_argument(
        "--tip-grating",
        action="store_true",
        help="give the sensor a tip force grating (its sensitivity and range chosen against the "
        "noise) and check the design with it",
    )
    parser.add_argument(
        "--tip-mass-g",
        type=non_negative_float,
        default=None,
        help="the tip's mass for the weight check (default: sensor.tip_mass_g of --config)",
    )
    parser.add_argument(
        "--write",
        type=Path,
        metavar="YAML",
        help="write the robot configuration with the designed sensor here (what `palpate sim`, "
        "`emulate`, `trial` and `teleop` read: a scene's `robot:`, `--config`)",
    )


def inputs(
    args: argparse.Namespace, stack: StackConfig, scene: SceneConfig
) -> tuple[tuple[float, float], DesignConstraints, DesignSpace]:
    unit = UNITS[args.unit]
    lo, hi = args.modulus_range
    thickness = None if math.isinf(args.thickness_mm) else args.thickness_mm * MM
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
        max_depth_ratio=_depth_ratio(args),
        held_across=args.pose == "any",
        tip_force_resolution=None if args.lumen_mm is None else args.tip_resolution_mn * 1e-3,
        post_buckling_travel=scene.campaign.post_buckling,
        grating_centres_from_tip=s.grating_centres_from_tip(),
        grating_length=s.grating_length,
    )
    lengths = args.length_range_mm
    space = DesignSpace(
        fiber_radii=tuple(r * 1e-6 for r in args.fiber_radii_um),
        fiber_modulus=s.fiber_modulus,
        wire_modulus=s.wire_modulus,
        wire_diameters=tuple(d * 1e-6 for d in args.wire_diameters_um),
        wire_counts=tuple(int(n) for n in args.wire_counts),
        tip_radii=tuple(r * 1e-3 for r in args.tip_radii_mm),
        length_range=(lengths[0] * 1e-3, lengths[1] * 1e-3),
    )
    return (lo * unit, hi * unit), constraints, space


def _depth_ratio(args: argparse.Namespace) -> float:
    if args.max_depth_ratio is not None:
        return float(args.max_depth_ratio)
    return LAW_DEPTH_RATIO if args.lumen_mm is not None else DesignConstraints.max_depth_ratio


def _lumen(args: argparse.Namespace) -> Lumen | None:
    if args.lumen_mm is None:
        return None
    try:
        return Lumen(args.lumen_mm * MM, args.clearance_mm * MM)
    except ValueError as exc:
        raise InputError(f"--lumen-mm/--clearance-mm: {exc}") from None


def search(
    args: argparse.Namespace,
    modulus_range: tuple[float, float],
    constraints: DesignConstraints,
    space: DesignSpace,
) -> tuple[DesignResult, LumenReport | None]:
    """The design search; with ``--lumen-mm`` in the lumen's space, spanning the range with
    as few sensors as it takes (the first one is the design the command goes on with)."""
    lumen = _lumen(args)
    if lumen is None:
        return design_sensor(modulus_range, constraints, space), None
    try:
        space = lumen.space(space)
    except ValueError as exc:
        raise InputError(f"--lumen-mm: {exc}") from None
    span = span_range(modulus_range, constraints, space)
    result = span.designs[0] if span.designs else design_sensor(modulus_range, constraints, space)
    return result, LumenReport(lumen, span, constraints, args.unit)


def tip_grating(
    args: argparse.Namespace, result: DesignResult, noise_pm: float
) -> TipGratingChoice | None:
    assert result.evaluation is not None
    p_cr = result.evaluation.critical_load
    if args.lumen_mm is not None:
        try:
            return tip_grating_for_resolution(p_cr, noise_pm, args.tip_resolution_mn * 1e-3)
        except ValueError as exc:
            raise InputError(f"--tip-resolution-mn: {exc}") from None
    return choose_tip_grating(p_cr, noise_pm) if args.tip_grating else None
