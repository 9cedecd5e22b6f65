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

from palpate.campaigns.campaign import campaign_trials
from palpate.campaigns.designcheck import (
    CheckSettings,
    DesignVerdict,
    design_scene,
    design_verdict,
    designed_stack,
    run_check,
)
from palpate.commands.design_inputs import inputs, register, search, tip_grating
from palpate.config import load, load_stack, resolve
from palpate.config.loader import InputError, write_yaml
from palpate.config.scene import SceneConfig
from palpate.config.schema import StackConfig
from palpate.estimation.design import DesignConstraints, DesignResult
from palpate.estimation.design.tipgrating import TipGratingChoice
from palpate.estimation.design.weight import SAG_LIMIT, WeightCheck, weight_check
from palpate.estimation.section import composite_section
from palpate.progress import progress_bar
from palpate.reports.design import CheckRun, payload, print_report
from palpate.reports.lumen import LumenReport
from palpate.simulation.trial import TrialOutcome

EXIT_NO_DESIGN = 2
__all__ = ["DesignOutcome", "evaluate", "register", "run"]  # register: the arguments


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
    if args.lumen_mm is not None:
        tip += f" --lumen-mm {args.lumen_mm:g} --tip-resolution-mn {args.tip_resolution_mn:g}"
    if args.pose == "any":
        tip += " --pose any"
    if args.tip_mass_g is not None:
        tip += f" --tip-mass-g {args.tip_mass_g:g}"
    lo, hi = args.modulus_range
    return (
        f"Written by `palpate design --modulus-range {lo:g}:{hi:g} --unit {args.unit}"
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
        advice = ""
        if not weight.ok:
            advice = (
                ": use it pointing vertically or with the fiber bending in a horizontal plane "
                "(docs/lung.md)"
            )
            if tip is not None:  # a tilted beam's sag fools a strain threshold, not the load
                advice += (
                    "; tilted, read its buckling from the tip load's plateau "
                    "(campaign.detector: tip, docs/invivo.md)"
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
    lumen: LumenReport | None = None

    def as_dict(self) -> dict[str, Any]:
        w = self.weight
        extra = {**_tip_payload(self.tip), **({} if w is None else {"weight": w.as_dict()})}
        if self.lumen is not None:
            extra["lumen"] = self.lumen.as_dict()
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
    modulus_range, constraints, space = inputs(args, stack, base)
    result, lumen = search(args, modulus_range, constraints, space)
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
        tip = tip_grating(args, result, max(base.fidelity.fbg_noise_pm, 1e-3))
        sensor_range = result.evaluation.modulus_range
        sim_stack = designed_stack(sim_stack, sensor_range, tip, args.tip_mass_g)
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
    return DesignOutcome(result, constraints, check, tip, weight, verdict, lumen)


def run(args: argparse.Namespace) -> int:
    found = evaluate(args)
    if args.json:
        print(json.dumps(found.as_dict(), indent=2))
    else:
        print(found.verdict.headline())
        if found.lumen is not None:
            print(found.lumen.text())
        print_report(found.result, found.constraints, found.check)
        _print_tip(found.tip, found.weight, args.write)
    if not found.result.success:
        return EXIT_NO_DESIGN
    return 0 if found.verdict.usable is not False else 1
