"""The probing floor benchmark: the exact-surface prober agrees with the world's surface, makes
probing no slower on the virtual clock, and leaves the shipped prober untouched afterwards."""

from __future__ import annotations

import math

import numpy as np
import pytest

import palpate.simulation.trial
from benchmarks.patching import patched
from benchmarks.probing import (
    ExactSurfaceGeometry,
    faster_drive,
    prober_hooks,
    trial_subset,
)
from palpate.config import load_stack
from palpate.robot import kinematics
from palpate.robot.probe_plan import ProbeGeometry, ProbeSettings
from palpate.robot.probe_result import Touch
from palpate.sim.world import Surface
from palpate.simulation.trial import run_sim_trial

STACK = load_stack()


def test_exact_prediction_puts_the_tip_on_the_true_surface() -> None:
    tube = STACK.tube("bent30")
    base = ProbeGeometry(
        tube,
        tip_radius=STACK.sensor.tip_radius,
        translation_limits=STACK.drive.translation_limits,
        roll_limits=STACK.drive.roll_limits,
        bending_mode=lambda length: (0.0, 0.0, 0.0),
    )
    pose = kinematics.forward(tube, 0.3, tube.flush_translation + 40e-3)
    tilt = math.radians(20.0)  # the plane tilted 20 deg about an axis across the tangent
    t = np.asarray(pose.tangent)
    across = np.cross(t, [1.0, 0.0, 0.0])
    across /= np.linalg.norm(across)
    normal = -(math.cos(tilt) * t + math.sin(tilt) * across)
    surface = Surface(point=np.asarray(pose.sensor_tip), normal=normal)
    exact = ExactSurfaceGeometry(base, surface)
    settings = ProbeSettings(offsets=(0.1,), touch_strain=25e-6, speed=2.5e-3, fast_speed=5e-3)
    depth = 0.12e-3
    touches = [Touch(0.3, 0.0, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), depth=depth)]
    for roll in (0.0, 0.3, 0.6):
        x, slack = exact.predict(touches, roll, settings)
        assert slack == 0.0
        centre = np.asarray(kinematics.forward(tube, roll, x - depth).sensor_tip)
        gap = float(np.dot(centre - surface.point, surface.normal))
        assert gap == pytest.approx(STACK.sensor.tip_radius, abs=1e-6)
    assert exact.tube is base.tube  # the same kinematics and limits
    assert exact.roll_limits == base.roll_limits


@pytest.mark.slow
def test_exact_surface_probes_no_slower_and_the_hooks_go_away() -> None:
    specs, scene, stack = trial_subset(quick=True, seed=0)
    spec = specs[1]  # a 10 deg tilt on the 15 deg tube, sideways
    original = palpate.simulation.trial.prober_for
    shipped = run_sim_trial(spec, scene, stack)
    with patched(prober_hooks(exact=True)):
        assert palpate.simulation.trial.prober_for is not original
        exact = run_sim_trial(spec, scene, stack)
    assert palpate.simulation.trial.prober_for is original
    again = run_sim_trial(spec, scene, stack)
    assert (again.probing_time, again.modulus("joint")) == (
        shipped.probing_time,
        shipped.modulus("joint"),
    )
    assert exact.state == shipped.state == "done"
    assert 0.0 < exact.probing_time < shipped.probing_time  # simulated seconds: deterministic
    assert exact.true_misalignment is not None
    assert math.degrees(exact.true_misalignment) < 1.0


def test_faster_drive_scales_every_limit() -> None:
    fast = faster_drive(STACK, 2.0).drive
    assert fast.max_speed == pytest.approx(2 * STACK.drive.max_speed)
    assert fast.max_accel == pytest.approx(2 * STACK.drive.max_accel)
    assert fast.max_roll_speed == pytest.approx(2 * STACK.drive.max_roll_speed)
    assert fast.max_roll_accel == pytest.approx(2 * STACK.drive.max_roll_accel)
