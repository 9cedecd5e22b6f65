"""Design a sensor for a tissue modulus range, then try it on simulated phantoms across the range.

``palpate design --modulus-range 1:10 --unit kPa`` proposes the fiber, wires, tip radius and
exposed length (``estimation.design``), prints the predicted indentation at buckling at both
ends of the range with every check's margin, then runs a short simulated bench campaign with
the proposed sensor on phantoms spread over the range (``--no-sim`` skips it). The first line
says whether the proposal is usable (``palpate.campaigns.designcheck.design_verdict``: every
phantom estimated within ``--tolerance-pct``, no trial failing, the tip's sag within its limit)
and why not; ``--json`` has ``usable`` and ``reasons``. Exit 0 for a usable (or unchecked)
design, 1 for one that is not usable, 2 when no design satisfies the constraints (the message
names the failing constraint).
"""

from __future__ import annotations

import argparse
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from palpate.argtypes import non_negative_int, positive_int
from palpate.campaigns.campaign import campaign_trials, default_workers
from palpate.campaigns.designcheck import (
    DEFAULT_TOLERANCE,
    UNITS,
    CheckSettings,
    DesignVerdict,
    design_scene,
    design_verdict,
    designed_stack,
    run_check,
)
from palpate.campaigns.executors import add_executor_arguments
from palpate.config import load, load_stack, resolve
from palpate.config.loader import InputError, write_yaml
from palpate.config.optics import MM
from palpate.config.scene import SceneConfig
from palpate.config.schema import StackConfig
from palpate.estimation.design import (
    DesignConstraints,
    DesignResult,
    DesignSpace,
    design_sensor,
)
from palpate.estimation.design.tipgrating import TipGratingChoice, choose_tip_grating
from palpate.estimation.design.weight import SAG_LIMIT, WeightCheck, weight_check
from palpate.estimation.section import composite_section
from palpate.progress import progress_bar
from palpate.reports.design import CheckRun, payload, print_report
from palpate.sensor.strain import strain_noise
from palpate.simulation.trial import TrialOutcome
from palpate.wire.dynamixel import TICKS_PER_REV

EXIT_NO_DESIGN = 2


def _floats(text: str, what: str) -> tuple[float, ...]:
    try:
        values = tuple(float(v) for v in text.split(",") if v.strip())
    except ValueError:
        raise InputError(f"{what}: expected comma-separated numbers, got {text!r}") from None
    if not values:
        raise InputError(f"{what}: empty list")
    return values


def _pair(text: str, what: str) -> tuple[float, float]:
    parts = text.split(":")
    try:
        lo, hi = (float(p) for p in parts)
    except ValueError:
        raise InputError(f"{what}: expected MIN:MAX, got {text!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo <= hi):
        raise InputError(f"{what}: need 0 < MIN <= MAX, got {text!r}")
    return lo, hi


def register(parser: argparse.ArgumentParser) -> None:
    _add_tissue_arguments(parser)
    _add_space_arguments(parser)
    _add_check_arguments(parser)


def _add_tissue_arguments(parser: argparse.ArgumentParser) -> None:
    """The tissue to design for and what the design must resolve."""
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


def _add_space_arguments(parser: argparse.ArgumentParser) -> None:
    """The candidates the search considers."""
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
    parser.add_argument(
        "--tolerance-pct",
        type=float,
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
        type=float,
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


def _inputs(
    args: argparse.Namespace, stack: StackConfig, scene: SceneConfig
) -> tuple[tuple[float, float], DesignConstraints, DesignSpace]:
    unit = UNITS[args.unit]
    lo, hi = _pair(args.modulus_range, "--modulus-range")
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
        post_buckling_travel=scene.campaign.post_buckling,
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


def _written_note(args: argparse.Namespace) -> str:
    tip = " --tip-grating" if args.tip_grating else ""
    if args.tip_mass_g is not None:
        tip += f" --tip-mass-g {args.tip_mass_g:g}"
    return (
        f"Written by `palpate design --modulus-range {args.modulus_range} --unit {args.unit}"
        f"{tip}`:\nthe robot configuration ({args.config}) with the designed sensor."
    )


def _tip_payload(tip: TipGratingChoice | None) -> dict[str, object]:
    return {} if tip is None else {"tip_grating": tip.as_dict()}


def _print_tip(
    tip: TipGratingChoice | None, weight: WeightCheck | None, written: Path | None
) -> None:
    if tip is not None:
        print(
            f"\ntip grating: {tip.sensitivity_pm_per_mn:g} pm/mN, range {tip.range_mn:.3g} mN, "
            f"element {tip.compliance_mm_per_n:.3g} mm/N, resolution {tip.resolution_mn:.3g} mN "
            f"({tip.resolution_share:.2%} of P_cr at 1 sigma)"
        )
    if weight is not None:
        advice = (
            ""
            if weight.ok
            else (
                ": use it pointing vertically or with the fiber bending in a horizontal plane "
                "(docs/lung.md)"
            )
        )
        print(f"weight: held across, {_sag_text(weight)}{advice}")
    if written is not None:
        print(f"wrote {written}")


def _sag_text(weight: WeightCheck) -> str:
    verdict = "within" if weight.ok else "beyond"
    limit = weight.tip_mass_limit * 1e3
    lighter = (
        f"a tip under {_two_digits_down(limit):g} g would be within"
        if limit > 0
        else "the beam's own weight sags it beyond, whatever its tip"
    )
    return (
        f"the tip sags {weight.sag * 1e3:.3g} mm ({weight.sag_over_length:.1%} of L, {verdict} "
        f"{SAG_LIMIT:.1%}; {lighter})"
    )


def _two_digits_down(x: float) -> float:
    """``x`` > 0 to two significant digits, rounded down (a limit printed is one that holds)."""
    scale = 10.0 ** (math.floor(math.log10(x)) - 1)
    return math.floor(x / scale) * scale


@dataclass(frozen=True)
class DesignOutcome:
    """What ``palpate design`` found: the search's result, its constraints, the simulated
    check (its trials, none when skipped), the tip grating and weight checks, and the verdict
    (``usable``, ``reasons``, ``conditions``); :meth:`as_dict` is what ``--json`` prints."""

    result: DesignResult
    constraints: DesignConstraints
    check: CheckRun
    tip: TipGratingChoice | None
    weight: WeightCheck | None
    verdict: DesignVerdict

    def as_dict(self) -> dict[str, Any]:
        w = self.weight
        extra = {**_tip_payload(self.tip), **({} if w is None else {"weight": w.as_dict()})}
        return {**self.verdict.as_dict(), **payload(self.result, self.constraints, self.check),
                **extra}  # fmt: skip


def evaluate(args: argparse.Namespace) -> DesignOutcome:
    """The search, the designed robot configuration (written with ``--write``), the weight
    check and the simulated check, from the command's arguments (``palpate.design`` builds
    them from keywords)."""
    stack = load_stack(args.config)
    base = load(SceneConfig, args.scene if args.scene else resolve("scenes/bench.yaml"))
    if args.moduli < 1 or args.lengths < 1:
        raise InputError("--moduli and --lengths must be >= 1")
    if args.contact_uncertainty_mm < 0:
        raise InputError("--contact-uncertainty-mm must be >= 0")
    modulus_range, constraints, space = _inputs(args, stack, base)
    result = design_sensor(modulus_range, constraints, space)
    outcomes: list[TrialOutcome] = []
    wall = 0.0
    tip: TipGratingChoice | None = None
    weight: WeightCheck | None = None
    if result.success:
        assert result.evaluation is not None
        assert result.length_window is not None
        scene, sim_stack = design_scene(
            result.evaluation, result.length_window, stack, base, _settings(args)
        )
        if args.tip_grating:
            noise = base.fidelity.fbg_noise_pm
            tip = choose_tip_grating(result.evaluation.critical_load, max(noise, 1e-3))
        sim_stack = designed_stack(sim_stack, modulus_range, tip, args.tip_mass_g)
        s = sim_stack.sensor
        section = composite_section(
            s.fiber_radius, s.fiber_modulus, s.wire_radius, s.wire_modulus, s.wire_count
        )
        weight = weight_check(s.tip_mass, s.linear_mass, section.EI, s.exposed_length)
        if args.write is not None:
            write_yaml(sim_stack, args.write, _written_note(args))
        if not args.no_sim:
            outcomes, wall = _run_sim(scene, sim_stack, args)
    verdict = design_verdict(
        result.success,
        None if args.no_sim else outcomes,
        None if weight is None else weight.ok,
        "" if weight is None else _sag_text(weight),
        args.tolerance_pct / 100,
    )
    check = CheckRun(outcomes, wall, args.unit, args.executor)
    return DesignOutcome(result, constraints, check, tip, weight, verdict)


def run(args: argparse.Namespace) -> int:
    found = evaluate(args)
    if args.json:
        print(json.dumps(found.as_dict(), indent=2))
    else:
        print(found.verdict.headline())
        print_report(found.result, found.constraints, found.check)
        _print_tip(found.tip, found.weight, args.write)
    if not found.result.success:
        return EXIT_NO_DESIGN
    return 0 if found.verdict.usable is not False else 1
