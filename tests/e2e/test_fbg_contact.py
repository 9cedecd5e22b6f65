"""FBG-based contact (``campaign.contact: fbg``): the sensor itself says when it touches.

The axial pre-load compresses the fiber as soon as the tip pushes on the tissue, so the mean
grating strain crossing ``RigSettings.fbg_contact_strain`` marks contact without the force scale
or camera event. The fiber senses force, not touch: the mark comes when the tissue pushes back
with P = EA * threshold, i.e. after the indentation that force takes (Hertz: large on soft
tissue). It must never come before the touch, and no later than that indentation.
"""

from __future__ import annotations

import dataclasses
import math

import pytest

from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.robot.rig import RigSettings
from palpate.robot.trial.setup import sensor_section
from palpate.simulation.trial import TrialSpec, run_sim_trial
from palpate.simulation.world import BENCH_COLUMN

STACK = load_stack()
BENCH = load(SceneConfig, resolve("scenes/bench.yaml"))


def _scene(contact: str) -> SceneConfig:
    fidelity = dataclasses.replace(BENCH.fidelity, contact_uncertainty_mm=0.0)
    campaign = dataclasses.replace(BENCH.campaign, contact=contact)
    return dataclasses.replace(BENCH, fidelity=fidelity, campaign=campaign)


def _spec(sample: str, modulus_kpa: float) -> TrialSpec:
    return TrialSpec(
        f"{sample}-fbg", "bench", sample, modulus_kpa * 1e3, 0.45, BENCH_COLUMN, "downward",
        0.0, 46e-3, 11,
    )  # fmt: skip


@pytest.mark.slow
def test_fbg_contact_lands_just_after_the_true_touch() -> None:
    for sample, modulus_kpa in (("S8", 314.53), ("S7", 1122.86)):
        event = run_sim_trial(_spec(sample, modulus_kpa), _scene("event"), STACK)
        fbg = run_sim_trial(_spec(sample, modulus_kpa), _scene("fbg"), STACK)
        assert event.state == fbg.state == "done", (event.reason, fbg.reason)
        assert event.estimate is not None
        assert fbg.estimate is not None
        x_event = event.marks.x_contact
        x_fbg = fbg.marks.x_contact
        assert x_event is not None
        assert x_fbg is not None
        lag = x_fbg - x_event
        # never before the touch (the event has no uncertainty here), and no later than the
        # half-space Hertz indentation under the threshold force (10 % for the layer and the
        # large-indentation law) plus a few control ticks of stage travel
        bound = 1.1 * _hertz_depth(modulus_kpa * 1e3) + 3 * STEP
        assert 0.0 <= lag <= bound, (sample, lag, bound)
        # the paper's delta (Eq. 14) shrinks by that lag: FBG contact biases E high
        assert fbg.estimate.delta < event.estimate.delta


STEP = BENCH.campaign.indent_speed_mm_per_s * 1e-3 / BENCH.control_rate_hz  # m per control tick


def _hertz_depth(modulus: float, poisson: float = 0.45) -> float:
    """Indentation at which the tissue pushes back with the FBG contact threshold's force."""
    force = sensor_section(STACK).EA * RigSettings().fbg_contact_strain
    e_star = modulus / (1 - poisson**2)
    return (3 * force / (4 * e_star * math.sqrt(STACK.sensor.tip_radius))) ** (2 / 3)
