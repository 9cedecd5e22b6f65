"""The simulated check of a sensor design: the proposed sensor on the robot, a short bench
campaign on phantoms across the modulus range, and how far its estimates land from the truth.

``palpate design`` (:mod:`palpate.commands.design`) proposes the design with
``design`` and prints; this module builds the scene (:func:`design_scene`), runs its
``campaign_trials`` (:func:`run_check`) and summarises the errors per estimation method
(:func:`error_summary`).
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from palpate.campaigns.campaign import median_abs_relative_error, run_campaign
from palpate.campaigns.executors import open_executor
from palpate.config.loader import InputError
from palpate.config.sample import SampleConfig
from palpate.config.scene import SceneConfig
from palpate.config.schema import StackConfig, TipGratingConfig
from palpate.sensor_design import DesignEvaluation
from palpate.sensor_design.tipgrating import TipGratingChoice
from palpate.sensor_design.weight import linear_mass
from palpate.simulation.trial import TrialOutcome, TrialSpec

UNITS: dict[str, float] = {"Pa": 1.0, "kPa": 1e3, "MPa": 1e6}

DEFAULT_TOLERANCE = 0.20
"""The largest |relative error| of the joint fit on a phantom for the design to be usable."""

METHODS = ("paper", "joint")
"""The estimates shown: the paper's single point (Eqs. 13-14) and the contact-point-free fit."""


@dataclass(frozen=True)
class CheckSettings:
    """The phantoms and the campaign of the check (the ``palpate design`` options)."""

    unit: str  # of the phantoms' names: a key of UNITS
    moduli: int  # phantoms across the range
    lengths: int  # exposed lengths per phantom
    poisson: float
    thickness_mm: float  # inf: a half-space
    imperfection: float  # initial bow w0/L of the sensor
    contact_uncertainty_mm: float  # contact-detection error (1 sigma)


def campaign_lengths(length: float, window: tuple[float, float], count: int) -> tuple[float, ...]:
    """The exposed lengths (m) the check simulates: the proposed ``length``, the two ends of the
    ``window`` where the hardware passes every check, and ``count - 3`` more between the ends
    (geometric); the proposal alone when ``count`` is 1 or the window is the proposal alone
    (a design on its checks' edge). A window is tested at its ends, not asserted.

    >>> [round(v * 1e3, 1) for v in campaign_lengths(0.045, (0.031, 0.0925), 3)]
    [31.0, 45.0, 92.5]
    """
    if count <= 1 or window[0] == window[1]:
        return (length,)
    between = np.geomspace(window[0], window[1], max(count - 1, 2))
    return tuple(sorted({float(v) for v in (*between, length)}))


def design_scene(
    ev: DesignEvaluation,
    window: tuple[float, float],
    stack: StackConfig,
    base: SceneConfig,
    settings: CheckSettings,
) -> tuple[SceneConfig, StackConfig]:
    """The proposed sensor on the robot, and a bench campaign on phantoms across the range.

    The detector threshold comes from the design (the paper's 300 ue is for a sensor 100x
    stiffer: its axial pre-load alone is 140 ue), and the travel guard from the predicted
    indentation."""
    d = ev.design
    sensor = dataclasses.replace(
        stack.sensor,
        fiber_radius_mm=d.fiber_radius * 1e3,
        wire_count=d.wire_count,
        wire_radius_mm=d.wire_radius * 1e3,
        tip_radius_mm=d.tip_radius * 1e3,
        exposed_length_mm=d.exposed_length * 1e3,
    )
    if ev.threshold is None:
        raise InputError("the design's buckling is not detectable: no detector threshold")
    c = base.campaign
    travel_mm = 1e3 * (3.0 * ev.delta_soft + ev.delta_bias) + c.post_buckling_mm + 0.5
    campaign = dataclasses.replace(
        c,
        kind="bench",
        samples=(),
        exposed_lengths_mm=tuple(
            round(v * 1e3, 1) for v in campaign_lengths(d.exposed_length, window, settings.lengths)
        ),
        repeats=1,
        detector="paper",
        detector_threshold_ue=ev.threshold * 1e6,
        max_travel_past_contact_mm=max(c.max_travel_past_contact_mm, travel_mm),
    )
    fidelity = dataclasses.replace(
        base.fidelity,
        imperfection_w0_over_l=settings.imperfection,
        contact_uncertainty_mm=settings.contact_uncertainty_mm,
    )
    scene = dataclasses.replace(
        base, name="design", samples=_phantoms(ev, settings), fidelity=fidelity, campaign=campaign
    )
    return scene, dataclasses.replace(stack, sensor=sensor)


REFERENCE_WAVELENGTH_NM = (
    1525.0  # the strain-free reference grating a tip grating's compensation uses
)


def designed_stack(
    stack: StackConfig,
    modulus_range: tuple[float, float],
    tip: TipGratingChoice | None,
    tip_mass_g: float | None = None,
) -> StackConfig:
    """The robot configuration with the designed sensor (``stack``'s, from :func:`design_scene`):
    its designed range (Pa) stated, its beam's mass from the fiber and wires, the tip's mass
    ``tip_mass_g`` (None: the configuration's), and with ``tip`` a tip grating,
    temperature-compensated by a strain-free reference grating the board sends."""
    s = stack.sensor
    sensor = dataclasses.replace(
        s,
        tip_mass_g=s.tip_mass_g if tip_mass_g is None else tip_mass_g,
        designed_range_kpa=(modulus_range[0] / 1e3, modulus_range[1] / 1e3),
        linear_mass_g_per_m=1e3 * linear_mass(s.fiber_radius, s.wire_count, s.wire_radius),
    )
    if tip is None:
        return dataclasses.replace(stack, sensor=sensor)
    grating = TipGratingConfig(
        sensitivity_pm_per_mn=tip.sensitivity_pm_per_mn,
        range_mn=tip.range_mn,
        compliance_mm_per_n=tip.compliance_mm_per_n,
    )
    fbg = stack.fbg
    if fbg.reference_wavelength_nm is None:
        fbg = dataclasses.replace(fbg, reference_wavelength_nm=REFERENCE_WAVELENGTH_NM)
    return dataclasses.replace(
        stack,
        sensor=dataclasses.replace(sensor, tip_grating=grating),
        fbg=fbg,
        board=dataclasses.replace(stack.board, has_reference=True),
    )


def _phantoms(ev: DesignEvaluation, settings: CheckSettings) -> tuple[SampleConfig, ...]:
    """``settings.moduli`` samples spread geometrically over the design's modulus range."""
    unit = UNITS[settings.unit]
    lo, hi = ev.modulus_range
    n = settings.moduli
    moduli = np.geomspace(lo, hi, max(1, n)) if n > 1 else np.array([lo])
    thickness = None if math.isinf(settings.thickness_mm) else settings.thickness_mm
    return tuple(
        SampleConfig(
            name=f"E{e / unit:.3g}{settings.unit}",
            modulus_kpa=float(e) / 1e3,
            poisson=settings.poisson,
            thickness_mm=thickness,
        )
        for e in moduli
    )


def run_check(
    specs: list[TrialSpec],
    scene: SceneConfig,
    stack: StackConfig,
    *,
    executor: str,
    workers: int,
    scheduler: str | None,
    progress: Callable[[TrialOutcome], None] | None = None,
) -> tuple[list[TrialOutcome], float]:
    """Run the check's trials (``campaign_trials`` of the scene) on the named executor:
    (outcomes, wall time in s)."""
    t0 = time.perf_counter()
    with open_executor(executor, max(1, workers), scheduler) as pool:
        outcomes = run_campaign(specs, scene, stack, executor=pool, progress=progress)
    return outcomes, time.perf_counter() - t0


NARROWING_STEPS = 3
"""Bisections (in log length) towards each end of the window whose trials fail: each runs the
phantoms at one more length, and leaves the window's edge within (ratio)^(1/8) of the truth."""


MIDDLE_TOLERANCE = 0.05
"""A length tried within 5 % of the window's geometric middle stands for the middle."""


@dataclass(frozen=True)
class SimulatedWindow:
    """The exposed lengths whose simulated trials all pass, about the proposal.

    Attributes:
        lengths: (min, max) in m, contiguous about the proposed length; None when the
            proposal's own trials fail.
        failed: each length tried whose trials did not all pass, with what failed there.
    """

    lengths: tuple[float, float] | None
    failed: tuple[tuple[float, str], ...]

    @property
    def middle(self) -> float | None:
        """The window's geometric middle (m): the length to use."""
        return None if self.lengths is None else math.sqrt(self.lengths[0] * self.lengths[1])

    def holds(self, length: float) -> bool:
        lo, hi = self.lengths or (math.inf, -math.inf)
        return lo - 1e-9 <= length <= hi + 1e-9

    def as_dict(self) -> dict[str, object]:
        return {
            "simulated_window_mm": None
            if self.lengths is None
            else [round(v * 1e3, 2) for v in self.lengths],
            "failed_at": [{"length_mm": round(v * 1e3, 2), "why": why} for v, why in self.failed],
        }


def narrowed_window(
    length: float,
    outcomes: list[TrialOutcome],
    run_at: Callable[[float], list[TrialOutcome]],
    tolerance: float = DEFAULT_TOLERANCE,
    steps: int = NARROWING_STEPS,
) -> tuple[list[TrialOutcome], SimulatedWindow]:
    """The window of lengths whose trials pass (:func:`length_failures`), found from the
    check's ``outcomes`` at the proposal and the window's ends, narrowed towards each end that
    fails by bisection: ``run_at(L)`` simulates the phantoms at L; then its middle, when no
    length tried stands for it. Returns every outcome (the new ones appended) and the window
    (none when the proposal's or the middle's trials fail)."""
    outcomes = list(outcomes)
    why = {v: length_failures(os, tolerance) for v, os in by_length(outcomes).items()}
    proposal = min(why, key=lambda v: abs(v - length))
    if why[proposal]:
        return outcomes, SimulatedWindow(None, tuple((v, w) for v, w in sorted(why.items()) if w))
    ends = []
    for side in (-1.0, 1.0):
        good, bad = proposal, None
        for v in sorted((v for v in why if side * (v - proposal) > 0), key=lambda v: side * v):
            if why[v]:  # outward from the proposal, the first length that fails
                bad = v
                break
            good = v
        for _ in range(steps):
            if bad is None:
                break
            new = run_at(math.sqrt(good * bad))
            if not new or new[0].spec.exposed_length in why:  # rounding met a length tried
                break
            tried = new[0].spec.exposed_length
            outcomes += new
            why[tried] = length_failures(new, tolerance)
            good, bad = (good, tried) if why[tried] else (tried, bad)
        ends.append(good)
    middle = math.sqrt(ends[0] * ends[1])
    if min(abs(math.log(v / middle)) for v in why) > MIDDLE_TOLERANCE:
        new = run_at(middle)
        if new:
            middle = new[0].spec.exposed_length
            outcomes += new
            why[middle] = length_failures(new, tolerance)
    failed = tuple((v, w) for v, w in sorted(why.items()) if w)
    if why.get(middle):  # the window's middle fails where its ends pass: no window
        return outcomes, SimulatedWindow(None, failed)
    return outcomes, SimulatedWindow((ends[0], ends[1]), failed)


def by_length(outcomes: list[TrialOutcome]) -> dict[float, list[TrialOutcome]]:
    """The outcomes grouped by their exposed length (m)."""
    groups: dict[float, list[TrialOutcome]] = {}
    for o in outcomes:
        groups.setdefault(o.spec.exposed_length, []).append(o)
    return groups


def length_failures(outcomes: list[TrialOutcome], tolerance: float = DEFAULT_TOLERANCE) -> str:
    """What fails among one length's trials, as the verdict names it ("" when they pass: every
    phantom done, with an estimate within ``tolerance``; :func:`design_verdict`)."""
    return "; ".join(design_verdict(True, outcomes, None, tolerance=tolerance).reasons)


def relative_error(o: TrialOutcome, method: str) -> float | None:
    """(estimate - truth) / truth of one trial; None when it has no estimate."""
    m = o.modulus(method)
    return None if m is None else (m - o.spec.modulus) / o.spec.modulus


def error_summary(outcomes: list[TrialOutcome], method: str) -> dict[str, float | None]:
    """Median and worst absolute relative error over the trials, for one method."""
    errors = [abs(e) for e in (relative_error(o, method) for o in outcomes) if e is not None]
    return {
        "median_abs_relative_error": median_abs_relative_error(outcomes, method),
        "max_abs_relative_error": max(errors, default=None),
    }


@dataclass(frozen=True)
class DesignVerdict:
    """Whether a proposed design works, from its own checks: ``usable`` (None when it was not
    checked in simulation), the reasons it is not (or why it is unchecked), and the conditions
    it is usable under (a tip that sags held across: only pointing vertically or bending in a
    horizontal plane; the paper's own sensor sags 5 % of L held across, and worked)."""

    usable: bool | None
    reasons: tuple[str, ...]
    conditions: tuple[str, ...] = ()

    def as_dict(self) -> dict[str, object]:
        return {
            "usable": self.usable,
            "reasons": list(self.reasons),
            "conditions": list(self.conditions),
        }

    def headline(self) -> str:
        """The first line of ``palpate design``'s report."""
        only = "; usable only " + "; ".join(self.conditions) if self.conditions else ""
        if self.usable:
            return (
                "USABLE design: its simulated check estimates every phantom within tolerance" + only
            )
        if self.usable is None:
            return "UNCHECKED design: " + "; ".join(self.reasons) + only
        return "NOT USABLE: " + "; ".join(self.reasons)


def design_verdict(
    found: bool,
    outcomes: list[TrialOutcome] | None,
    sag_ok: bool | None,
    sag_text: str = "",
    tolerance: float = DEFAULT_TOLERANCE,
    window: SimulatedWindow | None = None,
    allowed: tuple[float, float] | None = None,
) -> DesignVerdict:
    """The verdict on a proposal (``found``: the search found one) from its simulated check's
    ``outcomes`` (None: skipped), its weight check (``sag_ok``, None without one; ``sag_text``
    says by how much) and the ``tolerance`` on the joint fit's |relative error|. With the
    ``window`` of lengths whose trials pass, narrower than the ``allowed`` one its checks
    give, only the trials within it are judged and the design is usable only there."""
    if not found:
        return DesignVerdict(False, ("no design satisfies the constraints",))
    conditions: tuple[str, ...] = ()
    if sag_ok is False:
        conditions = (
            f"pointing vertically or bending in a horizontal plane (held across, {sag_text})",
        )
    if outcomes is None:
        return DesignVerdict(None, ("simulated check skipped",), conditions)
    if window is not None and window.lengths is not None and window.failed:
        (lo, hi), middle = window.lengths, window.middle or 0.0
        checks = (
            ""
            if allowed is None
            else f" (its checks allow {allowed[0] * 1e3:.1f}-{allowed[1] * 1e3:.1f} mm)"
        )
        conditions += (
            f"at exposed lengths {lo * 1e3:.1f}-{hi * 1e3:.1f} mm, {middle * 1e3:.1f} mm the "
            f"middle{checks}",
        )
        outcomes = [o for o in outcomes if window.holds(o.spec.exposed_length)]
    faulted = [o.spec.sample for o in outcomes if o.state != "done"]
    missing = [o.spec.sample for o in outcomes if o.modulus("joint") is None]
    wrong = [
        f"{o.spec.sample} {100 * e:+.0f} %"
        for o in outcomes
        if (e := relative_error(o, "joint")) is not None and abs(e) > tolerance
    ]
    reasons: list[str] = []
    if faulted:
        reasons.append(f"trials that did not complete: {', '.join(faulted)}")
    if missing:
        reasons.append(f"no estimate on {len(missing)} of {len(outcomes)}: {', '.join(missing)}")
    if wrong:
        reasons.append(f"errors beyond +-{100 * tolerance:.0f} %: {', '.join(wrong)}")
    return DesignVerdict(not reasons, tuple(reasons), conditions)
