"""Convex samples on the bent tubes (issue 25): with the radius believed, probing fits that
sphere and indents square to it; with the radius unknown the trial ends ``unreachable`` and says
why (one tube's touches on a sphere fit a plane tilted across its cone)."""

from __future__ import annotations

import dataclasses
import math

import pytest

from palpate.config import load, load_stack, resolve
from palpate.config.sample import UNKNOWN, AssumedConfig
from palpate.config.scene import SceneConfig
from palpate.estimation.trial.inputs import belief_fields
from palpate.simulation.result import estimator_inputs
from palpate.simulation.trial import TrialSpec, run_sim_trial, trial_geometry, trial_sample

STACK = load_stack()
SCENE = load(SceneConfig, resolve("scenes/oblique/convex.yaml"))
SAMPLE = "S8-R30-t10"


def spec(tube: str = "bent30") -> TrialSpec:
    modulus = next(s.modulus for s in SCENE.samples if s.name == SAMPLE)
    return TrialSpec(
        f"{SAMPLE}-{tube}",
        "robot",
        SAMPLE,
        modulus,
        0.45,
        STACK.tube(tube),
        "downward",
        0.0,
        42e-3,
        2,
    )


def believing(assumed: AssumedConfig) -> SceneConfig:
    samples = tuple(dataclasses.replace(s, assumed=assumed) for s in SCENE.samples)
    return dataclasses.replace(SCENE, samples=samples)


def test_a_believed_radius_finds_the_normal_of_a_convex_sample_and_indents_square() -> None:
    out = run_sim_trial(spec(), SCENE, STACK)
    assert out.state == "done", out.reason
    assert out.probe is not None
    assert out.probe.model == "sphere"
    assert out.probe.radius == pytest.approx(30e-3, rel=1e-9)  # the belief's, the tip's off
    assert out.true_misalignment is not None
    assert math.degrees(out.true_misalignment) < 1.0  # the world's angle at the indentation
    assert out.joint is not None
    assert out.joint.modulus is not None
    assert abs(out.joint.modulus / out.spec.modulus - 1) < 0.06


def test_the_contact_law_takes_the_believed_surfaces_effective_radius() -> None:
    s = spec()
    inputs = estimator_inputs(s, SCENE, STACK, trial_geometry(STACK, s, trial_sample(SCENE, s)))
    tip = STACK.sensor.tip_radius
    assert inputs.surface_radius == pytest.approx(30e-3)
    assert inputs.contact_radius == pytest.approx(1.0 / (1.0 / tip + 1.0 / 30e-3))
    assert inputs.law().tip_radius == pytest.approx(inputs.contact_radius)
    assert inputs.belief().tip_radius == pytest.approx(inputs.contact_radius)


def test_without_the_radius_a_convex_sample_ends_unreachable_and_says_why() -> None:
    out = run_sim_trial(spec(), believing(AssumedConfig(curvature_radius_mm="unknown")), STACK)
    assert out.state == "unreachable", out.reason
    assert "no orthogonal pose" in out.reason
    assert "convex surface gives such touches too" in out.reason
    assert out.probe is not None
    assert out.probe.model == "plane"


def test_the_bench_is_told_a_radius_only_where_its_trial_states_one() -> None:
    """On the bench there is no truth: a left-out radius is unknown (a flat fit)."""
    stated = belief_fields(
        AssumedConfig(curvature_radius_mm=(27, 33)), thickness=UNKNOWN, bonded=UNKNOWN, poisson=0.45
    )
    assert stated["surface_radius"] == pytest.approx(30e-3)
    assert "surface_radius" not in belief_fields(
        AssumedConfig(), thickness=UNKNOWN, bonded=UNKNOWN, poisson=0.45
    )
