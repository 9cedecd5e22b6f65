"""The robot on a positioning stage (issue 58): surfaces in their own coordinates, and a tube,
roll and stage pose that put the sensor on a point along its normal."""

from __future__ import annotations

import math

import numpy as np
import pytest

from palpate.config.schema import TubeConfig
from palpate.maps.surfaces import Dome, Lumen, TiltedPlane
from palpate.robot.kinematics import body_points, forward, tube_tip_in_bend_plane
from palpate.robot.positioner import MAX_RESIDUAL, Approach, Positioner, place, place_with_tube

R = 1.3e-3  # the lumen sensor's tip radius
PAPER = [
    TubeConfig(
        name=f"bent{a}",
        tip_angle_deg=a,
        straight_length_mm=40,
        arc_length_mm=40,
        flush_translation_mm=0,
        compliance_mm_per_n=0,
    )
    for a in (0, 15, 30, 50)
]
LUMEN90 = TubeConfig(
    name="lumen90",
    tip_angle_deg=90,
    straight_length_mm=10,
    arc_length_mm=2.5 * math.pi / 2,
    flush_translation_mm=0,
    compliance_mm_per_n=0,
)
AIRWAY = Lumen(origin=(0.0, 0.0, 0.0), axis=(1.0, 0.0, 0.0), radius=6e-3)
STAGE = Positioner(x=(-0.05, 0.05), y=(-4e-3, 4e-3), z=(-4e-3, 4e-3))


def how(exposed: float, surface: object = AIRWAY, **changes: object) -> Approach:
    """The lumen sensor's approach, ``exposed`` m out at contact, 0.5 mm clear at the start."""
    kw: dict = {"standoff": 0.5e-3, "translation_limits": (0.0, 0.2), **changes}
    return Approach(tip_radius=R, exposed_length=exposed, surface=surface, **kw)


def test_each_surface_puts_its_points_where_its_coordinates_say_and_faces_out() -> None:
    plane = TiltedPlane(origin=(0, 0, 0), normal=(0, 1, 1), first=(1, 0, 0))
    p = plane.at(2e-3, 3e-3)
    assert p.normal == pytest.approx(np.array([0, 1, 1]) / math.sqrt(2))
    assert float(np.linalg.norm(p.point)) == pytest.approx(math.hypot(2e-3, 3e-3))
    assert plane.clearance(p.point + 1e-3 * p.normal)[0] == pytest.approx(1e-3)
    dome = Dome(apex=(0, 0, 0), axis=(0, 0, 1), radius=10e-3)
    q = dome.at(10e-3 * math.pi / 2, 0.0)  # a quarter of a great circle from the apex
    assert q.point == pytest.approx([10e-3, 0.0, -10e-3], abs=1e-12)
    assert q.normal == pytest.approx([1.0, 0.0, 0.0], abs=1e-12)
    w = AIRWAY.at(5e-3, 6e-3 * math.pi)  # half a turn round the wall
    assert np.linalg.norm(w.point[1:]) == pytest.approx(6e-3)
    assert np.dot(w.normal[1:], w.point[1:]) == pytest.approx(-6e-3)  # toward the axis
    assert AIRWAY.clearance([[0.0, 0.0, 0.0], [1.0, 0.0, 7e-3]]) == pytest.approx([6e-3, -1e-3])


def test_surfaces_refuse_what_is_not_a_surface() -> None:
    with pytest.raises(ValueError, match="radius"):
        Lumen(origin=(0, 0, 0), axis=(1, 0, 0), radius=0.0)
    with pytest.raises(ValueError, match="axis"):
        Dome(apex=(0, 0, 0), axis=(0, 0, 0), radius=1e-3)
    with pytest.raises(ValueError, match="far pole"):
        Dome(apex=(0, 0, 0), axis=(0, 0, 1), radius=1e-3).at(4e-3, 0.0)


def test_body_points_run_along_the_tube_to_the_sensor_tip() -> None:
    tube = PAPER[3]
    pts = body_points(tube, 0.3, 0.01)
    tip, _ = tube_tip_in_bend_plane(tube)
    pose = forward(tube, 0.3, 0.01)
    assert pts[0] == pytest.approx([0.0, 0.0, 0.0])
    assert pts[-1] == pytest.approx(pose.sensor_tip)
    assert np.min(np.linalg.norm(pts - pose.tube_tip, axis=1)) == pytest.approx(0.0, abs=1e-12)
    steps = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    assert steps.max() < 2.0e-3  # a path, not scattered points
    assert float(np.linalg.norm(tip)) == pytest.approx(float(np.linalg.norm(pose.tube_tip)))


@pytest.mark.parametrize("turn", [0.0, 1.0, 2.5, 4.0, 5.9])
def test_a_right_angle_tube_meets_an_airway_wall_along_its_normal(turn: float) -> None:
    target = AIRWAY.at(20e-3, turn * 6e-3)
    p = place([*PAPER, LUMEN90], target, STAGE, how(2e-3, AIRWAY))
    assert p.reachable, p.reason
    assert p.tube == "lumen90"
    assert p.residual == pytest.approx(0.0, abs=1e-9)
    pose = forward(LUMEN90, p.roll, p.contact_translation)
    centre = pose.sensor_tip + p.base  # where the stage and joints put the tip sphere
    assert centre == pytest.approx(target.point + R * target.normal, abs=1e-12)
    assert -float(target.normal @ pose.tangent) == pytest.approx(1.0)
    start = forward(LUMEN90, p.roll, p.start_translation).sensor_tip + p.base
    assert AIRWAY.clearance(start)[0] - R == pytest.approx(0.5e-3)  # the standoff
    assert p.clearance >= 0.0


def test_the_papers_tubes_do_not_meet_an_airway_wall_square_on_and_say_so() -> None:
    target = AIRWAY.at(20e-3, 1.0e-3)
    p = place(PAPER, target, STAGE, how(2e-3, AIRWAY))
    assert not p.reachable
    assert p.residual > math.radians(30)
    wide = Positioner(x=(-0.1, 0.1), y=(-0.1, 0.1), z=(-0.1, 0.1))
    q = place(PAPER[:2], target, wide, how(2e-3, AIRWAY))
    assert q.status == 1
    assert "oblique" in q.reason
    assert q.residual > math.radians(70)


def test_a_sensor_longer_than_the_airway_is_wide_is_refused() -> None:
    target = AIRWAY.at(20e-3, 0.0)
    p = place_with_tube(LUMEN90, target, STAGE, how(42e-3, AIRWAY))
    assert p.status in (2, 5)  # the stage cannot back it off, or it would cut the far wall
    wide = Positioner(x=(-0.05, 0.05), y=(-0.1, 0.1), z=(-0.1, 0.1))
    q = place_with_tube(LUMEN90, target, wide, how(42e-3, AIRWAY))
    assert q.status == 5
    assert q.clearance < 0.0


def test_the_stage_and_translation_limits_are_guards() -> None:
    target = AIRWAY.at(20e-3, 0.0)
    short = Positioner(x=(-1e-3, 1e-3), y=(-4e-3, 4e-3), z=(-4e-3, 4e-3))
    p = place_with_tube(LUMEN90, target, short, how(2e-3, AIRWAY))
    assert p.status == 2
    q = place_with_tube(LUMEN90, target, STAGE, how(2e-3, translation_limits=(0.0, 1e-3)))
    assert q.status == 3


def test_a_tilted_plane_is_met_square_on_by_the_tube_whose_cone_holds_its_normal() -> None:
    # a plane facing back and down-left at 30 degrees off -x: bent30's cone holds -n
    n = np.array([-math.cos(math.radians(30)), 0.0, math.sin(math.radians(30))])
    plane = TiltedPlane(origin=(0.09, 0.0, -0.03), normal=n)
    wide = Positioner(x=(-0.1, 0.1), y=(-0.1, 0.1), z=(-0.1, 0.1))
    p = place(PAPER, plane.at(1e-3, -2e-3), wide, how(20e-3, plane))
    assert p.reachable
    assert p.tube == "bent30"
    assert p.residual < MAX_RESIDUAL


def test_no_tube_is_a_clear_error() -> None:
    with pytest.raises(ValueError, match="at least one tube"):
        place([], AIRWAY.at(0.0, 0.0), STAGE, how(1e-3))
    with pytest.raises(ValueError, match="tip_radius"):
        Approach(tip_radius=0.0, exposed_length=1e-3, standoff=0.0, translation_limits=(0, 1))
    with pytest.raises(ValueError, match="travel"):
        Positioner(x=(1.0, -1.0))
