"""Inverse kinematics on oblique surfaces: the cone apex, reachability by angle and position."""

from __future__ import annotations

import math

import numpy as np
import pytest

from palpate.config.sample import SampleConfig
from palpate.config.schema import StackConfig
from palpate.robot import kinematics
from palpate.simulation.placement import place_sample

STACK = StackConfig()
R_TIP = 3.5e-3
LIMITS = {"tip_radius": R_TIP, "translation_limits": (0.0, 0.08), "roll_limits": (-3.5, 3.5)}


def _nominal(tube_name: str, roll: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    pose = kinematics.forward(STACK.tube(tube_name), roll, 0.042)
    return pose.sensor_tip + R_TIP * pose.tangent, pose.tangent


@pytest.mark.parametrize("tube_name", ["bent15", "bent30", "bent50"])
def test_every_roll_of_a_bent_tube_passes_through_its_apex(tube_name: str) -> None:
    tube = STACK.tube(tube_name)
    apex = kinematics.apex(tube)
    assert apex is not None
    assert apex[1] == apex[2] == 0.0
    for roll in np.linspace(-3, 3, 7):
        pose = kinematics.forward(tube, float(roll), 0.0)
        offset = apex - pose.tube_tip
        assert np.linalg.norm(np.cross(offset, pose.tangent)) < 1e-12
    assert kinematics.apex(STACK.tube("straight")) is None


@pytest.mark.parametrize("tube_name", ["bent15", "bent30", "bent50"])
@pytest.mark.parametrize("tilt", [5.0, 15.0, 25.0])
@pytest.mark.parametrize("radius_mm", [None, 60.0])
def test_a_tilted_surface_placed_reachable_is_met_square(
    tube_name: str, tilt: float, radius_mm: float | None
) -> None:
    tube = STACK.tube(tube_name)
    target, t0 = _nominal(tube_name)
    sample = SampleConfig(
        name="s", modulus_kpa=300, tilt_deg=tilt, tilt_azimuth_deg=None,
        curvature_radius_mm=radius_mm,
    )  # fmt: skip
    surface = place_sample(tube, 0.0, (target, t0), sample, seed=0)
    assert math.degrees(math.acos(-float(surface.normal @ t0))) == pytest.approx(tilt)
    radius = None if radius_mm is None else radius_mm * 1e-3
    ik = kinematics.solve_for_tube(tube, surface.point, surface.normal, radius=radius, **LIMITS)
    assert ik.reachable, ik.reason
    assert ik.residual < 1e-6
    # the advance puts the tip sphere on the surface, square to it
    pose = kinematics.forward(tube, ik.roll, ik.advance)
    normal = (
        surface.normal
        if radius is None
        else ik.contact_point - (surface.point - radius * surface.normal)
    )
    normal = normal / np.linalg.norm(normal)
    assert float(normal @ pose.tangent) == pytest.approx(-1.0, abs=1e-9)
    assert np.linalg.norm(pose.sensor_tip - R_TIP * normal - ik.contact_point) < 1e-9


def test_the_miss_grows_with_the_tilt_about_the_tubes_apex() -> None:
    tube = STACK.tube("bent15")
    target, t0 = _nominal("bent15")
    misses = []
    for tilt in (5.0, 15.0, 25.0):
        sample = SampleConfig(name="s", modulus_kpa=300, tilt_deg=tilt, tilt_azimuth_deg=None)
        surface = place_sample(tube, 0.0, (target, t0), sample, seed=0)
        ik = kinematics.solve_for_tube(tube, surface.point, surface.normal, **LIMITS)
        misses.append(ik.miss)
    # all lines of the tube meet at its apex, ~66 mm behind the contact: miss ~ 66 mm sin(tilt)
    assert misses == pytest.approx(
        [0.066 * math.sin(math.radians(t)) for t in (5, 15, 25)], rel=0.1
    )


def test_reachability_checks_angle_and_position() -> None:
    tube = STACK.tube("bent15")
    target, t0 = _nominal("bent15")
    # the case: a normal 3.7 deg off the cone, reachable before only by its angle
    sample = SampleConfig(name="s", modulus_kpa=300, tilt_deg=18.7, tilt_azimuth_deg=0.0)
    surface = place_sample(tube, 0.0, (target, t0), sample, seed=0)
    loose = kinematics.solve_for_tube(tube, surface.point, surface.normal, **LIMITS)
    assert loose.reachable
    assert loose.residual > math.radians(2)
    angled = kinematics.solve_for_tube(
        tube, surface.point, surface.normal, max_residual=math.radians(2.0), **LIMITS
    )
    assert angled.status == 5
    assert not angled.reachable
    assert "angle" in angled.reason
    sample = SampleConfig(name="s", modulus_kpa=300, tilt_deg=20.0, tilt_azimuth_deg=None)
    surface = place_sample(tube, 0.0, (target, t0), sample, seed=0)
    far = kinematics.solve_for_tube(
        tube, surface.point, surface.normal, max_residual=math.radians(2.0), max_miss=0.01,
        **LIMITS,
    )  # fmt: skip
    assert far.residual < 1e-6
    assert far.miss > 0.01
    assert far.status == 6
    assert "position" in far.reason


def test_a_straight_tube_cannot_turn_to_a_tilted_surface() -> None:
    target, t0 = _nominal("straight")
    sample = SampleConfig(name="s", modulus_kpa=300, tilt_deg=15.0, tilt_azimuth_deg=None)
    surface = place_sample(STACK.tube("straight"), 0.0, (target, t0), sample, seed=0)
    ik = kinematics.inverse(
        [STACK.tube("straight")], surface.point, surface.normal,
        max_residual=math.radians(2.0), **LIMITS,
    )  # fmt: skip
    assert ik.status == 5
    assert math.degrees(ik.residual) == pytest.approx(15.0)
    # across the tube set the IK finds the tube whose cone holds the normal
    best = kinematics.inverse(
        STACK.tubes, surface.point, surface.normal, max_residual=math.radians(2.0), **LIMITS
    )
    assert best.reachable
    assert best.tube == "bent15"
    assert best.residual < 1e-6


def test_a_sphere_the_line_misses_is_unreachable() -> None:
    tube = STACK.tube("bent30")
    target, _t0 = _nominal("bent30")
    far_off = target + np.array([0.0, 0.2, 0.0])
    ik = kinematics.solve_for_tube(tube, far_off, np.array([0.0, 1.0, 0.0]), radius=5e-3, **LIMITS)
    assert ik.status == 1
    assert not ik.reachable
