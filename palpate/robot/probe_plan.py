"""The geometry and the decisions of probing: the touches' rolls, where the next touch can be,
the fitted surface and the orthogonal pose (``robot.probing`` runs them tick by tick).

A touch is the tip sphere's centre when the FBG's load reached the light-touch threshold, from
the kinematics and the stage encoder. The centres lie on the surface offset by the tip radius
plus the light touch's small depth, the same at every touch: that moves each centre along its
ray, and every ray of a bent tube comes from the cone's apex (``robot.kinematics.apex``), so a
plane through them keeps its normal. Rolling moves the tip on a circle about the base x axis:
the plane's tilt across the roll is known only through that circle's bow (the sagitta the
touches span), the tilt along it through their spread; :meth:`ProbeGeometry.roll_step` sizes
the roll by the bow.

Where the next touch can be (:meth:`ProbeGeometry.predict`): with one touch, anywhere within
``max_tilt`` of facing the tube; with two, the plane through them least tilted from facing the
tube, give or take ``max_tilt`` about their line; with three or more, the fitted plane give or
take three times its normal's uncertainty about the touches' centroid.
:meth:`ProbeGeometry.sweep_needs` turns that into the advance behind the surface on every ray a
roll sweeps. :meth:`ProbeGeometry.replan` fits the plane (or, with five touches or more that a
plane cannot explain, the sphere: ``estimation.pose.surface``) and asks the inverse kinematics of
the trial's tube for the roll and advance that meet it orthogonally, near where the plan aimed
(the first touch); reachable only within the angle and position tolerances.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..config.schema import TubeConfig
from ..estimation.beam.states import axial_strain
from ..estimation.contact.law import MAX_MISALIGNMENT
from ..estimation.pose.surface import SurfaceFit, SurfaceGeometry, fit_plane
from . import kinematics
from .indentation import TrialPlan
from .probe_fit import NORMAL_SIGMAS, allowed_residual, scaled_sigma, touch_surface
from .probe_result import ProbeResult, Touch

Vector = NDArray[np.float64]
FloatArray = NDArray[np.float64]
SWEEP_STEPS = 8  # rays checked along a roll for the retract before it
ROLL_MARGIN = math.radians(1.0)  # probe rolls stay this far inside the roll limits
SPREAD_STEP = 1e-6  # m, a touch moved along its ray for the spread of a prediction
MODE_STEP = 50e-6  # m of exposed length between the bending shapes the load is read with


@dataclass(frozen=True)
class ProbeSettings:
    """How a trial probes (SI: rad, m, m/s).

    Attributes:
        offsets: the rolls of the touches after the first, relative to the plan's roll.
        touch_strain: axial strain (compression) that is a touch; also the unit of the bow a
            touch or a free tip is judged by.
        touch_force: with a tip force grating, the tip load (N) that is a touch instead of the
            axial strain (a mN beam's axial strain is at the noise); None: the strain.
        speed: approach speed of the first touch; fast_speed for the moves between touches.
        decel: the stage's deceleration: once a touch has shown how deep the sample yields,
            later ones approach as fast as the stage stops within half that depth.
        clearance: kept between the tip and where the surface can be, when moving.
        max_tilt: the largest tilt of the surface from facing the tube the search allows for.
        sigma: a touch's uncertainty along its ray (m), for the normal's uncertainty.
        max_residual, max_miss: the tolerances of the orthogonal pose.
        standoff: where the trial's approach starts before the expected contact.
        replan: False measures and logs the misalignment but keeps the plan's pose.
        search: how far past the approach window the first touch looks for a sample that is
            not where the plan says (m).
        budget: simulated or real seconds probing may take (:func:`probe_budget`, from the
            drive's limits); past it the trial ends ``unreachable`` (inf: no budget).
        surface_radius: the radius (min, max; m) the operator believes a convex sample's
            surface has: the touches are fitted by a sphere of that radius
            (``estimation.pose.surface_belief``); None: a plane, or a sphere where the touches show
            one (the tilt across a tube's cone is not observable on a sphere of unknown radius).
    """

    offsets: tuple[float, ...]
    touch_strain: float
    speed: float
    fast_speed: float
    decel: float = math.inf  # m/s^2, the stage's; a seek may go as fast as it can stop in
    clearance: float = 0.2e-3
    max_tilt: float = math.radians(30.0)
    sigma: float = 10e-6
    max_residual: float = math.radians(2.0)
    max_miss: float = 30e-3
    standoff: float = 1e-3
    replan: bool = True
    budget: float = math.inf
    search: float = 0.0
    touch_force: float | None = None
    surface_radius: tuple[float, float] | None = None


class ProbeGeometry:
    """The trial tube's kinematics for probing: tip centres, predictions and the re-plan."""

    def __init__(
        self,
        tube: TubeConfig,
        *,
        tip_radius: float,
        translation_limits: tuple[float, float],
        roll_limits: tuple[float, float],
        bending_mode: Callable[[float], Sequence[float]],
        loads: Callable[[FloatArray, FloatArray], FloatArray] | None = None,
    ) -> None:
        """``bending_mode``: the gratings' onset bending shape at an exposed length (m)
        (``estimation.beam.states.onset_mode``), to take the beam's bow out of its load tick by
        tick; ``loads``: the axial strain P/EA of a record (advances (N,) m, strains (N, G))
        by the full non-linear beam state (``estimation.beam.states.infer_states``), for the fit
        of a touch (the onset shape is a few microstrain off once the bow has grown)."""
        self.tube = tube
        self.tip_radius = tip_radius
        self.translation_limits = translation_limits
        self.roll_limits = roll_limits
        self._mode = bending_mode
        self._modes: dict[int, Sequence[float]] = {}
        self.loads = loads

    def axial(self, strains: Sequence[float], advance: float) -> float:
        """The axial strain P/EA (compression positive) at a stage ``advance`` (m): the uniform
        part of ``strains`` once the bow along the onset shape at this exposed length is out
        (the shape moves along the gratings as the sensor comes out: a millimetre of length
        turns a 300 kPa sample's touch by ~60 um if the shape is not the one at hand)."""
        if not strains:
            return math.nan
        key = round((advance - self.tube.flush_translation) / MODE_STEP)
        if key not in self._modes:
            self._modes[key] = self._mode(key * MODE_STEP)
        return axial_strain(strains, self._modes[key])

    @property
    def can_probe(self) -> bool:
        """A bent tube: its rolls give different lines."""
        return self.tube.tip_angle > 0.0

    def roll_step(self, sagitta: float, plan_roll: float, plan_advance: float) -> float:
        """The roll (rad) either side of the plan that bows the tip's arc by ``sagitta`` (m) at
        the planned contact: the tip moves on a circle about the x axis, and the plane's tilt
        along the tube's bend is known only through that bow (at most 60 deg)."""
        c = kinematics.forward(self.tube, plan_roll, plan_advance).sensor_tip
        radial = math.hypot(float(c[1]), float(c[2]))
        if not radial > sagitta / 2:
            return math.radians(60.0) if radial > 0 else 0.0
        return min(math.acos(1.0 - sagitta / radial), math.radians(60.0))

    def probe_rolls(self, plan_roll: float, offsets: Sequence[float]) -> list[float]:
        """The touches' rolls: the plan's, then ``offsets`` from it, mirrored when that keeps
        them within the roll limits, else held a degree inside them (one roll for a straight
        tube)."""
        if not self.can_probe:
            return [plan_roll]
        lo, hi = self.roll_limits[0] + ROLL_MARGIN, self.roll_limits[1] - ROLL_MARGIN
        for sign in (1.0, -1.0):
            rolls = [plan_roll + sign * o for o in offsets]
            if all(lo <= r <= hi for r in rolls):
                return [plan_roll, *rolls]
        return [plan_roll] + [min(max(plan_roll + o, lo), hi) for o in offsets]

    def touch(self, roll: float, advance: float) -> Touch:
        pose = kinematics.forward(self.tube, roll, advance)
        c, t = pose.sensor_tip, pose.tangent
        return Touch(roll, advance, (c[0], c[1], c[2]), (t[0], t[1], t[2]))

    def advance_to(self, centres: SurfaceGeometry, roll: float) -> float:
        """The advance (m) at which the tip centre reaches the centres' surface at ``roll``."""
        pose = kinematics.forward(self.tube, roll, self.tube.flush_translation)
        return self.tube.flush_translation + centres.ray_hit(pose.tube_tip, pose.tangent)

    def predict(
        self, touches: list[Touch], roll: float, settings: ProbeSettings
    ) -> tuple[float, float]:
        """(advance, slack) m: where the next touch at ``roll`` is expected, and how far either
        side of it the surface can be (see the module docstring)."""
        model, line, tilt = _model(touches, settings.sigma)
        x = self.advance_to(model, roll)
        if not math.isfinite(x):
            x = touches[-1].advance
        spread = self._spread(touches, roll, x, settings.sigma) if len(touches) >= 3 else math.nan
        if math.isfinite(spread):
            return x, spread + 3.0 * settings.sigma
        c = np.asarray(self.touch(roll, x).centre)
        slack = _distance_to_line(c, line) * math.tan(min(tilt, settings.max_tilt))
        return x, slack + 3.0 * settings.sigma

    def _spread(self, touches: list[Touch], roll: float, x: float, sigma: float) -> float:
        """Three standard deviations (m) of the advance at which the fitted plane meets the ray
        at ``roll``: each touch moved by ``SPREAD_STEP`` along its own ray, the plane fitted again
        (first-order propagation, the touches' uncertainty ``sigma`` scaled up by their scatter
        as the fit's). Along the roll the touches pin the plane's slope well; across it (the
        circle's bow) less, and a ray that leaves the touches' line sideways sees that: a bound
        by direction, not the normal's whole uncertainty times the distance. NaN when a moved
        plane does not meet the ray."""
        c = np.array([t.centre for t in touches])
        rays = np.array([t.tangent for t in touches])
        hint = -rays.mean(axis=0)
        grads = []
        for i in range(len(touches)):
            q = c.copy()
            q[i] += SPREAD_STEP * rays[i]
            fit = fit_plane(q, sigma=sigma, hint=hint)
            if not fit.success or fit.centres is None:
                return math.nan
            grads.append((self.advance_to(fit.centres, roll) - x) / SPREAD_STEP)
        unmoved = fit_plane(c, sigma=sigma, hint=hint)  # its scatter scales sigma
        if not unmoved.success or unmoved.centres is None:
            return math.nan
        dof = len(touches) - 3
        noise = max(sigma, unmoved.rms * math.sqrt(len(touches) / dof)) if dof > 0 else sigma
        g = float(np.linalg.norm(grads))
        return 3.0 * noise * g if math.isfinite(g) else math.nan

    def sweep_needs(
        self, touches: list[Touch], start: float, end: float, settings: ProbeSettings
    ) -> tuple[list[float], list[float]]:
        """(rolls, advances): rays from roll ``start`` to ``end`` and, on each, the advance (m)
        behind where the surface can be, by ``clearance`` (the touches, and so the prediction,
        are their depth past the surface)."""
        rolls = np.linspace(start, end, SWEEP_STEPS + 1).tolist()
        depth = max(t.depth for t in touches)  # the touches are this far past the surface
        safe = []
        for roll in rolls:
            x, slack = self.predict(touches, roll, settings)
            safe.append(max(x - depth - slack - settings.clearance, self.translation_limits[0]))
        return rolls, safe

    def sweep_retract(
        self, touches: list[Touch], start: float, end: float, settings: ProbeSettings
    ) -> float:
        """The advance (m) behind the surface on every ray from roll ``start`` to ``end``."""
        lowest = touches[-1].advance - settings.clearance
        return min(lowest, *self.sweep_needs(touches, start, end, settings)[1])

    def replan(self, touches: list[Touch], plan: TrialPlan, settings: ProbeSettings) -> ProbeResult:
        """Fit the surface, find the orthogonal pose of this tube, decide reachability."""
        if not self.can_probe:
            why = "a straight tube meets the surface along one line at every roll"
            return self._unmeasured(touches, plan, settings, why)
        held = [t for t in touches if not t.slipped]
        if len(held) < 3:
            why = f"{len(touches) - len(held)} of {len(touches)} touches slipped"
            return self._unmeasured(touches, plan, settings, why)
        centres = np.array([t.centre for t in held])
        rays = np.array([t.tangent for t in held])
        fit = touch_surface(centres, rays, settings.sigma, settings.surface_radius, self.tip_radius)
        if not fit.success:
            return self._unmeasured(touches, plan, settings, fit.message)
        surface = fit.surface(self.tip_radius)
        normal_sigma = scaled_sigma(fit, settings.sigma)
        n0 = surface.normal_at(centres[0])
        target = centres[0] - self.tip_radius * n0
        ik = kinematics.solve_for_tube(
            self.tube, target, n0, tip_radius=self.tip_radius,
            translation_limits=self.translation_limits, roll_limits=self.roll_limits,
            radius=surface.radius, max_miss=settings.max_miss,
            max_residual=allowed_residual(settings.max_residual, normal_sigma),
        )  # fmt: skip
        move = ik.reachable and settings.replan
        roll = ik.roll if move else plan.roll
        depth = float(np.mean([t.depth for t in held]))  # the fit is this far past the surface
        advance = ik.advance - depth if move else plan.contact_advance
        if not settings.replan:  # measure only: the misalignment of the plan's own pose
            ik = _plan_pose(self, target, n0, surface.radius, plan)
        roll = nearest_turn(roll, touches[-1].roll, self.roll_limits)  # the way out's roll
        retract = self.sweep_retract(touches, touches[-1].roll, roll, settings)
        retract = min(retract, advance - settings.standoff - settings.clearance)
        n = surface.normal
        return ProbeResult(
            ik.reachable or not settings.replan,
            _reason(ik, settings, normal_sigma) + _curved_hint(ik, fit, settings),
            roll,
            advance,
            ik.residual,
            normal_sigma,
            ik.miss,
            (float(n[0]), float(n[1]), float(n[2])),
            fit.model,
            surface.radius,
            tuple(touches),
            retract,
        )

    def _unmeasured(
        self, touches: list[Touch], plan: TrialPlan, settings: ProbeSettings, why: str
    ) -> ProbeResult:
        contact = _found_contact(touches, plan)
        retract = min(touches[-1].advance, contact) - settings.standoff
        return ProbeResult(
            True, f"normal not measured: {why}", plan.roll, contact, 0.0,
            math.nan, 0.0, None, "none", None, tuple(touches), retract - settings.clearance,
        )  # fmt: skip


def _found_contact(touches: list[Touch], plan: TrialPlan) -> float:
    """The contact to approach without a normal: the plan's, unless the plan's own ray touched
    the surface (its first touch that held, where its load began) where the plan's approach
    would not meet it (before its stand-off or past half its window): a sample away from the
    plan is approached where it is, one where the plan says as planned."""
    for t in touches:
        if not t.slipped and abs(t.roll - plan.roll) <= plan.roll_tolerance:
            found = t.advance - t.depth
            lo = plan.contact_advance - plan.standoff
            hi = plan.contact_advance + 0.5 * plan.approach_window
            return plan.contact_advance if lo < found < hi else found
    return plan.contact_advance


def nearest_turn(roll: float, near: float, limits: tuple[float, float]) -> float:
    """``roll`` or a whole turn from it (the same line), whichever within ``limits`` is nearest
    ``near``: the way out never sweeps the long way round (nor is its retract planned over the
    long way: a sweep through a whole turn meets rays nearly along the surface)."""
    turns = [roll + k * math.tau for k in (-1, 0, 1)]
    inside = [r for r in turns if limits[0] <= r <= limits[1]] or [roll]
    return min(inside, key=lambda r: abs(r - near))


def _plan_pose(
    geo: ProbeGeometry, target: Vector, normal: Vector, radius: float | None, plan: TrialPlan
) -> kinematics.IKSolution:
    """The misalignment and miss of the plan's own roll on the measured surface."""
    pose = kinematics.forward(geo.tube, plan.roll, geo.tube.flush_translation)
    surface = SurfaceGeometry.make(target, normal, radius)
    hit = surface.offset(geo.tip_radius).ray_hit(pose.tube_tip, pose.tangent)
    centre = pose.tube_tip + hit * pose.tangent
    local = surface.normal_at(centre)
    residual = math.acos(max(-1.0, min(1.0, -float(local @ pose.tangent))))
    miss = float(np.linalg.norm(centre - geo.tip_radius * local - target))
    advance = geo.tube.flush_translation + hit
    return kinematics.IKSolution(geo.tube.name, plan.roll, advance, hit, residual, 0, centre, miss)


def _reason(ik: kinematics.IKSolution, settings: ProbeSettings, normal_sigma: float) -> str:
    found = f"residual {math.degrees(ik.residual):.2f} deg, miss {ik.miss * 1e3:.1f} mm"
    if ik.reachable and ik.residual > settings.max_residual:
        return f"pose found within the measured normal's uncertainty: {found}"
    if ik.reachable:
        return f"orthogonal pose found: {found}"
    allowed = allowed_residual(settings.max_residual, normal_sigma)
    capped = " = the cap" if allowed < settings.max_residual + NORMAL_SIGMAS * normal_sigma else ""
    limits = (
        f"tolerances {math.degrees(settings.max_residual):.1f} deg "
        f"+ {NORMAL_SIGMAS:g} x {math.degrees(normal_sigma):.2f} deg (the normal's 1-sigma), "
        f"at most {math.degrees(max(settings.max_residual, MAX_MISALIGNMENT)):.0f} deg"
        f"{capped}, {settings.max_miss * 1e3:.0f} mm"
    )
    return f"no orthogonal pose of tube {ik.tube}: {ik.reason} ({found}; {limits})"


def _curved_hint(ik: kinematics.IKSolution, fit: SurfaceFit, settings: ProbeSettings) -> str:
    """What else the touches may be: one tube's touches on a convex sphere fit a plane to a few
    micrometres, tilted across the tube's cone (``estimation.pose.surface_belief``)."""
    if ik.reachable or fit.model != "plane" or settings.surface_radius is not None:
        return ""
    return (
        "; a convex surface gives such touches too (its tilt across the tube's cone is not "
        "observable from one tube): with its radius believed (assumed.curvature_radius_mm) "
        "the touches are fitted by that sphere"
    )


def _model(
    touches: list[Touch], sigma: float
) -> tuple[SurfaceGeometry, tuple[Vector, Vector], float]:
    """The centres' plane the touches so far support, the line about which it may still turn
    and by how much (rad; ``inf``: by any angle, the search's bound applies). Three touches or
    more fix a plane up to three times its normal's 1-sigma angle about their centroid (three
    on one side of the roll leave it loose across)."""
    c = np.array([t.centre for t in touches])
    rays = np.array([t.tangent for t in touches])
    facing = -rays.mean(axis=0)
    if len(touches) >= 3:
        fit = fit_plane(c, sigma=sigma, hint=facing, directions=rays)
        if fit.success and fit.centres is not None:
            return fit.centres, (fit.centres.point, np.zeros(3)), 3.0 * fit.normal_sigma
    if len(touches) == 1:
        return SurfaceGeometry.make(c[0], facing), (c[0], np.zeros(3)), math.inf
    along = (c[1] - c[0]) / np.linalg.norm(c[1] - c[0])
    normal = facing - float(facing @ along) * along
    return SurfaceGeometry.make(c[0], normal), (c[0], along), math.inf


def _distance_to_line(p: Vector, line: tuple[Vector, Vector]) -> float:
    """Distance from ``p`` to the line (point, unit direction); a zero direction: the point."""
    q, d = line
    v = p - q
    return float(np.linalg.norm(v - float(v @ d) * d))
