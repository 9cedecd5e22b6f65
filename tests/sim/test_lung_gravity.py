"""Gravity on the lung scene's mN sensor (issue 28), per orientation, against beam theory: the
weight's share in the fiber's bending plane for each roll, and the free beam's sag under its tip
and its own weight from a direct integration of the bending moment."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid

from palpate.campaigns.campaign import campaign_trials
from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.estimation.beam.elastica.constants import P_CRIT
from palpate.robot import kinematics
from palpate.robot.trial.setup import sensor_section
from palpate.sim.gravity import BeamWeight, sensing_axis

LUNG = load(SceneConfig, resolve("scenes/lung/lung.yaml"))
STACK = load_stack(LUNG.robot)
SENSOR = STACK.sensor
EI = sensor_section(STACK).EI
L = SENSOR.exposed_length
WEIGHT = BeamWeight.of(SENSOR.tip_mass, SENSOR.linear_mass)


def cantilever_tip_deflection(tip: float, per_length: float, length: float) -> float:
    """w(L) of a cantilever under a tip load and a uniform load, integrating M/EI twice."""
    x = np.linspace(0.0, length, 20001)  # from the clamp
    moment = tip * (length - x) + per_length * (length - x) ** 2 / 2
    slope = cumulative_trapezoid(moment / EI, x, initial=0.0)
    return float(cumulative_trapezoid(slope, x, initial=0.0)[-1])


def in_plane_share(orientation: str, tube: str = "bent30") -> float:
    spec = next(
        s
        for s in campaign_trials(LUNG, STACK, 0)
        if s.orientation == orientation and s.tube.name == tube
    )
    pose = kinematics.forward(STACK.tube(tube), spec.roll, 0.0)
    return WEIGHT.across(sensing_axis(pose.tangent, spec.roll)).tip / WEIGHT.tip


def test_the_free_beams_sag_is_beam_theorys() -> None:
    sag = WEIGHT.pin_offset(EI, L)
    assert sag == pytest.approx(cantilever_tip_deflection(WEIGHT.tip, WEIGHT.per_length, L), 1e-3)
    # the design rule docs/lung.md states: sag / L = (20.19 / 3) W / P_cr for a tip weight W
    p_cr = P_CRIT * EI / L**2
    tip_only = BeamWeight(WEIGHT.tip, 0.0).pin_offset(EI, L)
    assert tip_only / L == pytest.approx(P_CRIT / 3 * WEIGHT.tip / p_cr, rel=1e-9)
    assert 0.15 < sag / L < 0.2  # 0.05 g on an 18 mN beam: it droops a sixth of its length


@pytest.mark.parametrize("tube", ["bent15", "bent30", "bent50"])
def test_the_weight_in_the_fibers_plane_per_orientation(tube: str) -> None:
    """The tube points the sensor down (or up) by its tip angle from the horizontal base axis:
    the weight across the beam in its bending plane is cos(angle) of it, of opposite signs for
    the downward and upward rolls; rolled sideways the bending plane is horizontal."""
    across = math.cos(STACK.tube(tube).tip_angle)
    assert in_plane_share("downward", tube) == pytest.approx(-across, abs=1e-9)
    assert in_plane_share("upward", tube) == pytest.approx(across, abs=1e-9)
    assert in_plane_share("sideways", tube) == pytest.approx(0.0, abs=1e-9)
