"""Designing a sensor, the service ``palpate design`` and ``palpate.design`` both call: a
:class:`DesignRequest` (``services.design_request``: the command's options as typed fields) in,
a :class:`DesignOutcome` out (the search, the simulated check, the verdict).

    >>> request = DesignRequest((300.0, 1100.0), thickness_mm=10.0, no_sim=True)
    >>> evaluate(request).result.success
    True
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

from palpate.campaigns.campaign import campaign_trials
from palpate.campaigns.designcheck import (
    UNITS,
    CheckSettings,
    DesignVerdict,
    SimulatedWindow,
    design_scene,
    design_verdict,
    designed_stack,
    narrowed_window,
    run_check,
)
from palpate.config import load, load_stack, resolve
from palpate.config.loader import InputError, write_yaml
from palpate.config.optics import MM
from palpate.config.scene import SceneConfig
from palpate.config.schema import StackConfig
from palpate.estimation.beam.section import composite_section
from palpate.progress import progress_bar
from palpate.reports.design import CheckRun, payload
from palpate.reports.lumen import LumenReport
from palpate.sensor.strain import strain_noise
from palpate.sensor_design import (
    DesignConstraints,
    DesignResult,
    DesignSpace,
    design_sensor,
)
from palpate.sensor_design.lumen import LAW_DEPTH_RATIO, Lumen, span_range
from palpate.sensor_design.tipgrating import (
    TipGratingChoice,
    choose_tip_grating,
    tip_grating_for_resolution,
)
from palpate.sensor_design.weight import SAG_LIMIT, WeightCheck, weight_check
from palpate.services.design_request import DesignRequest
from palpate.simulation.trial import TrialOutcome
from palpate.wire.dynamixel import TICKS_PER_REV

__all__ = ["DesignOutcome", "DesignRequest", "evaluate"]


def inputs(
    req: DesignRequest, stack: StackConfig, scene: SceneConfig
) -> tuple[tuple[float, float], DesignConstraints, DesignSpace]:
    unit = UNITS[req.unit]
    lo, hi = req.modulus_range
    thickness = None if math.isinf(req.thickness_mm) else req.thickness_mm * MM
    s = stack.sensor
    constraints = DesignConstraints(
        poisson=req.poisson,
        thickness=thickness,
        encoder_resolution=stack.drive.lead / TICKS_PER_REV,
        resolution_multiple=req.resolution_multiple,
        strain_limit=stack.fbg.strain_limit,
        strain_noise=strain_noise(
            scene.fidelity.fbg_noise_pm, stack.fbg.strain_coefficient_pm_per_ue
        ),
        imperfection=req.imperfection,
        max_depth_ratio=_depth_ratio(req),
        held_across=req.pose == "any",
        tip_force_resolution=None if req.lumen_mm is None else req.tip_resolution_mn * 1e-3,
        post_buckling_travel=scene.campaign.post_buckling,
        grating_centres_from_tip=s.grating_centres_from_tip(),
        grating_length=s.grating_length,
    )
    lengths = req.length_range_mm
    space = DesignSpace(
        fiber_radii=tuple(r * 1e-6 for r in req.fiber_radii_um),
        fiber_modulus=s.fiber_modulus,
        wire_modulus=s.wire_modulus,
        wire_diameters=tuple(d * 1e-6 for d in req.wire_diameters_um),
        wire_counts=tuple(int(n) for n in req.wire_counts),
        tip_radii=tuple(r * 1e-3 for r in req.tip_radii_mm),
        length_range=(lengths[0] * 1e-3, lengths[1] * 1e-3),
    )
    return (lo * unit, hi * unit), constraints, space


def _depth_ratio(req: DesignRequest) -> float:
    if req.max_depth_ratio is not None:
        return float(req.max_depth_ratio)
    return LAW_DEPTH_RATIO if req.lumen_mm is not None else DesignConstraints.max_depth_ratio


def _lumen(req: DesignRequest) -> Lumen | None:
    if req.lumen_mm is None:
        return None
    try:
        return Lumen(req.lumen_mm * MM, req.clearance_mm * MM)
    except ValueError as exc:
        raise InputError(f"--lumen-mm/--clearance-mm: {exc}") from None


def search(
    req: DesignRequest,
    modulus_range: tuple[float, float],
    constraints: DesignConstraints,
    space: DesignSpace,
) -> tuple[DesignResult, LumenReport | None]:
    """The design search; with ``--lumen-mm`` in the lumen's space, spanning the range with
    as few sensors as it takes (the first one is the design the command goes on with)."""
    lumen = _lumen(req)
    if lumen is None:
        return design_sensor(modulus_range, constraints, space), None
    try:
        space = lumen.space(space)
    except ValueError as exc:
        raise InputError(f"--lumen-mm: {exc}") from None
    span = span_range(modulus_range, constraints, space)
    result = span.designs[0] if span.designs else design_sensor(modulus_range, constraints, space)
    return result, LumenReport(lumen, span, constraints, req.unit)


def tip_grating(
    req: DesignRequest, result: DesignResult, noise_pm: float
) -> TipGratingChoice | None:
    assert result.evaluation is not None
    p_cr = result.evaluation.critical_load
    if req.lumen_mm is not None:
        try:
            return tip_grating_for_resolution(p_cr, noise_pm, req.tip_resolution_mn * 1e-3)
        except ValueError as exc:
            raise InputError(f"--tip-resolution-mn: {exc}") from None
    return choose_tip_grating(p_cr, noise_pm) if req.tip_grating else None


def _settings(req: DesignRequest) -> CheckSettings:
    return CheckSettings(
        unit=req.unit,
        moduli=req.moduli,
        lengths=req.lengths,
        poisson=req.poisson,
        thickness_mm=req.thickness_mm,
        imperfection=req.imperfection,
        contact_uncertainty_mm=req.contact_uncertainty_mm,
    )


def _run_sim(
    scene: SceneConfig, stack: StackConfig, req: DesignRequest
) -> tuple[list[TrialOutcome], float]:
    specs = campaign_trials(scene, stack, req.seed)
    bar = progress_bar(len(specs), "design check")

    def progress(o: TrialOutcome) -> None:
        bar.update(1)
        bar.set_postfix_str(o.spec.trial_id)

    outcomes, wall = run_check(
        specs,
        scene,
        stack,
        executor=req.executor,
        workers=req.workers,
        scheduler=req.scheduler,
        progress=progress,
    )
    bar.close()
    return outcomes, wall


def _window_check(
    scene: SceneConfig, stack: StackConfig, req: DesignRequest, length: float
) -> tuple[list[TrialOutcome], float, SimulatedWindow]:
    """The check at the proposed ``length`` and the window's ends, narrowed where an end fails
    (:func:`palpate.campaigns.designcheck.narrowed_window`): every trial, the wall time, the
    lengths whose trials pass."""
    outcomes, wall = _run_sim(scene, stack, req)
    walls = [wall]

    def run_at(at: float) -> list[TrialOutcome]:
        campaign = replace(scene.campaign, exposed_lengths_mm=(round(at * 1e3, 1),))
        more, w = _run_sim(replace(scene, campaign=campaign), stack, req)
        walls.append(w)
        return more

    outcomes, window = narrowed_window(length, outcomes, run_at, req.tolerance_pct / 100)
    return outcomes, sum(walls), window


def _to_write(stack: StackConfig, window: SimulatedWindow | None) -> StackConfig:
    """The configuration to write: at the middle of the lengths whose simulated trials pass,
    where they are narrower than its checks allow."""
    if window is None or window.middle is None or not window.failed:
        return stack
    sensor = replace(stack.sensor, exposed_length_mm=round(window.middle * 1e3, 1))
    return replace(stack, sensor=sensor)


def _written_note(req: DesignRequest) -> str:
    tip = " --tip-grating" if req.tip_grating else ""
    if req.lumen_mm is not None:
        tip += f" --lumen-mm {req.lumen_mm:g} --tip-resolution-mn {req.tip_resolution_mn:g}"
    if req.pose == "any":
        tip += " --pose any"
    if req.tip_mass_g is not None:
        tip += f" --tip-mass-g {req.tip_mass_g:g}"
    lo, hi = req.modulus_range
    return (
        f"Written by `palpate design --modulus-range {lo:g}:{hi:g} --unit {req.unit}"
        f"{tip}`:\nthe robot configuration ({req.config}) with the designed sensor."
    )


def _tip_payload(tip: TipGratingChoice | None) -> dict[str, object]:
    return {} if tip is None else {"tip_grating": tip.as_dict()}


def sag_text(weight: WeightCheck) -> str:
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
    with_tip_grating: DesignOutcome | None = None

    def headline(self) -> str:
        """The report's first line: the verdict, and where the plain request is not usable
        but a tip grating makes it so, the option that does."""
        alt = self.with_tip_grating
        if alt is None or not alt.verdict.usable:
            return self.verdict.headline()
        return (
            "NOT USABLE without a tip grating; with --tip-grating: "
            f"{alt.verdict.headline()} (without: {'; '.join(self.verdict.reasons)})"
        )

    def as_dict(self) -> dict[str, Any]:
        w = self.weight
        extra = {**_tip_payload(self.tip), **({} if w is None else {"weight": w.as_dict()})}
        if self.lumen is not None:
            extra["lumen"] = self.lumen.as_dict()
        if self.with_tip_grating is not None:
            extra["with_tip_grating"] = self.with_tip_grating.as_dict()
        return {**self.verdict.as_dict(), **payload(self.result, self.constraints, self.check),
                **extra}  # fmt: skip


def evaluate(req: DesignRequest) -> DesignOutcome:
    """The search, the designed robot configuration (written with ``write``), the weight
    check and the simulated check of a request (``palpate design``'s options, or
    ``palpate.design``'s keywords). A plain request whose simulated check fails is checked
    again with a tip grating (``with_tip_grating``), so the answer names the option that
    serves it, where one does."""
    found = _evaluated(req)
    plain = not req.tip_grating and not req.no_sim
    if plain and found.result.success and found.verdict.usable is False:
        tipped = replace(req, tip_grating=True, write=None)  # written as asked, or not at all
        return replace(found, with_tip_grating=_evaluated(tipped))
    return found


def _evaluated(req: DesignRequest) -> DesignOutcome:
    """:func:`evaluate` for ``req`` as it is asked."""
    stack = load_stack(req.config)
    base = load(SceneConfig, req.scene if req.scene else resolve("scenes/bench.yaml"))
    modulus_range, constraints, space = inputs(req, stack, base)
    result, lumen = search(req, modulus_range, constraints, space)
    outcomes: list[TrialOutcome] = []
    wall = 0.0
    window: SimulatedWindow | None = None
    tip: TipGratingChoice | None = None
    weight: WeightCheck | None = None
    if result.success:
        assert result.evaluation is not None
        assert result.length_window is not None
        scene, sim_stack = design_scene(
            result.evaluation, result.length_window, stack, base, _settings(req)
        )
        tip = tip_grating(req, result, max(base.fidelity.fbg_noise_pm, 1e-3))
        sensor_range = result.evaluation.modulus_range
        sim_stack = designed_stack(sim_stack, sensor_range, tip, req.tip_mass_g)
        s = sim_stack.sensor
        section = composite_section(
            s.fiber_radius, s.fiber_modulus, s.wire_radius, s.wire_modulus, s.wire_count
        )
        weight = weight_check(s.tip_mass, s.linear_mass, section.EI, s.exposed_length)
        if not req.no_sim:
            length = result.evaluation.design.exposed_length
            outcomes, wall, window = _window_check(scene, sim_stack, req, length)
        if req.write is not None:
            write_yaml(_to_write(sim_stack, window), req.write, _written_note(req))
    verdict = design_verdict(
        result.success,
        None if req.no_sim else outcomes,
        None if weight is None else weight.ok,
        "" if weight is None else sag_text(weight),
        req.tolerance_pct / 100,
        window,
        result.length_window,
    )
    check = CheckRun(outcomes, wall, req.unit, req.executor, window)
    return DesignOutcome(result, constraints, check, tip, weight, verdict, lumen)
