"""A map through the robot (issue 58): the tissue stays where it is and a positioner carries
the robot, as a lab's gantry on the bench or a guide sheath in the body does.

The patch is a plane in the robot's base frame (:func:`map_surface`) that faces the insertion
axis, tilted ``campaign.map_tilt_deg`` toward +z, so a tube of that tip angle at roll 0 meets it
square on; its own coordinates ``(u, v)`` are the map's ``(x, y)`` (u along the base frame's y).
A sample with a ``curvature_radius_mm`` makes it a convex dome of that radius with its apex
there (``(u, v)`` azimuthal equidistant about the apex): its normal turns from point to point,
and the world presses a sphere of that radius (the tissue under each point is the flat patch's
at the same ``(u, v)``, unrolled: model enough for a dome several times the patch's size).
For each point the plan picks, :meth:`ThroughRobot.place` solves the tube, roll and stage pose
that put the sensor on the point along its normal (:func:`robot.positioner.place` over the
robot file's tubes, the contact at the campaign's first exposed length), and the probe is a
robot trial there (:meth:`ThroughRobot.spec`): the world's tissue faces the way the patch does
at that point in the robot's frame, whatever the tube's residual angle, and the controller is
told none of it (with ``campaign.probe`` it touches to find the normal and re-plans its
roll). The stage moves only between trials, with the sensor back at its retract pose (every
trial ends there); its travel counts in the lab time at ``campaign.stage_speed_mm_per_s``.

A point no tube meets within 2 degrees is probed obliquely and its verdict says so (at most
``suspect``); a point the stage, the drive or the clearance refuses is a probe without a number
that says why. Each probe carries its normal error: the angle between the sensor's axis and the
surface's normal where it indented, the world's truth (``TrialOutcome.true_misalignment``)::

    reach = ThroughRobot.of(scene, stack)
    placed = reach.place((2e-3, -3e-3))
    placed.tube, math.degrees(placed.residual), placed.base
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from transforms3d.quaternions import mat2quat

from palpate.config.scene import SceneConfig
from palpate.config.schema import StackConfig, TubeConfig
from palpate.estimation.verdict import NORMAL_SIGMAS
from palpate.maps import Probe
from palpate.maps.surfaces import Dome, TiltedPlane
from palpate.robot import kinematics
from palpate.robot.positioner import Approach, Placement, Positioner, place
from palpate.robot.records.cdr import Transform
from palpate.simulation.trial import TrialOutcome
from palpate.simulation.world import TrialSpec

Point = tuple[float, float]
LATERAL = (0.0, 1.0, 0.0)  # the patch's u: the base frame's y
Vector = NDArray[np.float64]


def plane_normal(tilt: float) -> tuple[float, float, float]:
    """The patch's outward normal: facing the insertion axis (-x), tilted ``tilt`` (rad) toward
    +z, where a tube of tip angle ``tilt`` at roll 0 points (``robot.kinematics.tangent``)."""
    return (-math.cos(tilt), 0.0, math.sin(tilt))


MapSurface = TiltedPlane | Dome
STEP = 1e-6  # m along the surface: its local directions by a difference


def map_surface(scene: SceneConfig, stack: StackConfig) -> MapSurface:
    """The patch in the robot's base frame at stage zero: through the point the tube whose tip
    angle is nearest the tilt touches at roll 0 with the campaign's first exposed length out,
    facing :func:`plane_normal` there; a plane, or a convex dome whose apex that is when the
    sample has a ``curvature_radius_mm``."""
    c = scene.campaign
    tube = min(stack.tubes, key=lambda t: abs(t.tip_angle - c.map_tilt))
    n = np.asarray(plane_normal(c.map_tilt))
    contact = tube.flush_translation + c.exposed_lengths[0]
    centre = kinematics.forward(tube, 0.0, contact).sensor_tip
    apex = centre - stack.sensor.tip_radius * n
    radius = scene.campaign_samples()[0].curvature_radius
    if radius is None:
        return TiltedPlane(origin=apex, normal=n, first=LATERAL)
    return Dome(apex=apex, axis=n, radius=radius, first=LATERAL)


def local_frame(surface: MapSurface, point: Point) -> tuple[Vector, Vector, Vector]:
    """(e1, e2, n) at ``point``: the way ``u`` grows there (off the normal), ``n x e1``, and the
    outward normal."""
    here = surface.at(*point)
    n = here.normal
    step = surface.at(point[0] + STEP, point[1]).point - here.point
    e1 = step - float(step @ n) * n
    e1 = e1 / np.linalg.norm(e1)
    return e1, np.cross(n, e1), n


def true_normal(surface: MapSurface, point: Point, tilt: float, azimuth: float) -> Vector:
    """The tissue's true outward normal at ``point``: the surface's, tilted ``tilt`` (rad)
    toward ``azimuth`` (rad, about it from the way ``u`` grows toward ``v``): the sample's
    ``tilt_deg`` and ``tilt_azimuth_deg``, a patch registered that far wrong. Each point keeps
    its place; the tissue turns about it."""
    e1, e2, n = local_frame(surface, point)
    way = math.cos(azimuth) * e1 + math.sin(azimuth) * e2
    return np.asarray(math.cos(tilt) * n + math.sin(tilt) * way)


@dataclass(frozen=True)
class ThroughRobot:
    """How a map's probes reach the patch through the robot: the surface the plan believes in,
    the positioner's travel, the approach, the tubes to choose from, and how wrong the surface
    was registered (``tilt``, ``azimuth``, rad: :func:`true_normal`)."""

    surface: MapSurface
    stage: Positioner
    approach: Approach
    tubes: tuple[TubeConfig, ...]
    tilt: float = 0.0
    azimuth: float = 0.0

    @classmethod
    def of(cls, scene: SceneConfig, stack: StackConfig) -> ThroughRobot:
        c = scene.campaign
        surface = map_surface(scene, stack)
        sample = scene.campaign_samples()[0]
        travel = (-c.positioner_travel, c.positioner_travel)
        how = Approach(
            tip_radius=stack.sensor.tip_radius,
            exposed_length=c.exposed_lengths[0],
            standoff=c.standoff,
            translation_limits=stack.drive.translation_limits,
            surface=surface,
            roll_limits=stack.drive.roll_limits,
        )
        stage = Positioner(x=travel, y=travel, z=travel)
        tilt, azimuth = sample.tilt, sample.tilt_azimuth or 0.0
        return cls(surface, stage, how, tuple(stack.tubes), tilt, azimuth)

    def place(self, point: Point) -> Placement:
        """The tube, roll and stage pose for the patch's ``point`` (m)."""
        return place(self.tubes, self.surface.at(*point), self.stage, self.approach)

    def tube(self, placed: Placement) -> TubeConfig:
        """The tube a placement chose."""
        return next(t for t in self.tubes if t.name == placed.tube)

    def spec(self, spec: TrialSpec, placed: Placement, point: Point) -> TrialSpec:
        """The probe's trial (a bench probe's ``spec`` at ``point``) as a robot trial at the
        placement, the tissue facing its true normal there."""
        n = true_normal(self.surface, point, self.tilt, self.azimuth)
        return dataclasses.replace(
            spec,
            kind="robot",
            tube=self.tube(placed),
            roll=placed.roll,
            facing=(float(n[0]), float(n[1]), float(n[2])),
        )

    def frames(self, point: Point) -> list[Transform]:
        """``/tf`` of the probe at ``point``: ``world`` -> ``sample`` (the patch at its origin,
        its u, v and normal as x, y, z) and ``world`` -> ``base`` (the placement; stage zero
        where none was found)."""
        e1, e2, n = local_frame(self.surface, (0.0, 0.0))
        w, x, y, z = mat2quat(np.column_stack([e1, e2, n]))
        origin = self.surface.at(0.0, 0.0).point
        placed = self.place(point)
        base = placed.base if placed.status in (0, 1) else self.stage.home
        return [
            ("world", "sample", tuple(float(v) for v in origin), (x, y, z, w)),
            ("world", "base", tuple(float(v) for v in base), (0.0, 0.0, 0.0, 1.0)),
        ]

    def travel(self, last: Point | None, placed: Placement) -> float:
        """How far (m) the positioner moves the base to ``placed`` from the last probe's point's
        placement (from stage zero for the first, ``last`` None), along the line between."""
        start = self.stage.home if last is None else self.place(last).base
        return float(np.linalg.norm(placed.base - start))


def measured_tilt(outcome: TrialOutcome) -> float | None:
    """The largest tilt to the normal the trial's own touches allow (rad): the misalignment the
    estimator was told and ``NORMAL_SIGMAS`` of the measured normal's sigma; None where no
    normal was measured (no probing, or touches along one line)."""
    probe = outcome.probe
    if probe is None or probe.normal is None or not math.isfinite(probe.normal_sigma):
        return None
    return abs(outcome.misalignment) + NORMAL_SIGMAS * probe.normal_sigma


def refused(point: Point, placed: Placement) -> Probe:
    """The probe of a point the robot cannot reach: no number, and why."""
    return Probe(point[0], point[1], None, None, "none", (f"not reached: {placed.reason}",))


def oblique(probe: Probe, placed: Placement) -> Probe:
    """A probe pressed off its normal (placement status 1): its verdict says so, at most
    ``suspect``."""
    if placed.status != 1:
        return probe
    why = f"oblique: {math.degrees(placed.residual):.1f} deg from the surface normal"
    status = "suspect" if probe.status == "ok" else probe.status
    return dataclasses.replace(probe, status=status, reasons=(*probe.reasons, why))
