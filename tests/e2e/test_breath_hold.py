"""A lung trial under a ventilator (issue 42): the trial waits at the stand-off for a breath hold
that has just begun (the ventilator's gate, frame status bit 6), indents within it; the hold's
residual drift is measured from the tip grating, taken out of the record before the fit, and
the verdict says how far the surface moved."""

from __future__ import annotations

import dataclasses

import pytest

from palpate.campaigns.campaign import campaign_trials
from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.config.schema import StackConfig
from palpate.robot.records.log import read_log
from palpate.simulation.result import TrialOutcome
from palpate.simulation.trial import run_sim_trial

pytestmark = pytest.mark.slow  # a heavy module fixture: the quick subset leaves it out

SCENE = load(SceneConfig, resolve("scenes/invivo/breath-hold.yaml"))
STACK = load_stack(SCENE.robot)


def run_one(
    scene: SceneConfig,
    stack: StackConfig,
    sample: str,
    tmp_path_factory: pytest.TempPathFactory,
) -> TrialOutcome:
    """The scene's trial on ``sample`` through the 15 deg tube, downward."""
    spec = next(
        s
        for s in campaign_trials(scene, stack, 0)
        if s.sample == sample and s.tube.name == "bent15" and s.orientation == "downward"
    )
    return run_sim_trial(spec, scene, stack, log_dir=tmp_path_factory.mktemp("logs"))


def trial(scene: SceneConfig, tmp_path_factory: pytest.TempPathFactory) -> TrialOutcome:
    """N2: 2 kPa, 40 mm."""
    return run_one(scene, STACK, "N2", tmp_path_factory)


@pytest.fixture(scope="module")
def held(tmp_path_factory: pytest.TempPathFactory) -> TrialOutcome:
    return trial(SCENE, tmp_path_factory)


def test_the_trial_waits_for_a_breath_hold(held: TrialOutcome) -> None:
    assert held.state == "done", held.reason
    assert held.log_path is not None
    moves = [(tr["to"], tr["reason"]) for tr in read_log(held.log_path).of_kind("transition")]
    assert ("waiting", "at stand-off") in moves
    assert ("approach", "breath hold") in moves


def test_the_drift_is_measured_taken_out_and_reported(held: TrialOutcome) -> None:
    assert held.true_motion is not None
    assert held.motion is not None
    assert 0.05e-3 < held.motion <= held.true_motion  # toward the sensor, within its range
    assert held.joint is not None
    assert held.joint.modulus == pytest.approx(2e3, rel=0.05)
    assert held.verdict is not None
    assert held.verdict.status == "suspect"
    assert any(r.startswith("moved: the surface moved") for r in held.verdict.reasons)


def test_without_the_motion_check_the_drift_biases_the_fit(
    held: TrialOutcome, tmp_path_factory: pytest.TempPathFactory
) -> None:
    """The same trial, the campaign checking no motion: the record is fitted as it is."""
    campaign = dataclasses.replace(SCENE.campaign, motion_tolerance_mm=None)
    plain = trial(dataclasses.replace(SCENE, campaign=campaign), tmp_path_factory)
    assert plain.joint is not None
    assert held.joint is not None
    assert plain.motion == held.motion  # the same world, the same record
    assert plain.joint.modulus > 1.1 * 2e3  # the surface came toward the sensor: too stiff


def test_free_breathing_without_a_gate_gives_no_ok_trial(
    tmp_path_factory: pytest.TempPathFactory,
) -> None:
    """2 mm of breath along the axis and the heart's 1 mm, no gate: the surface moves through
    every contact, and no trial that saw it move past the tolerance is ok."""
    scene = load(SceneConfig, resolve("scenes/invivo/free-breathing.yaml"))
    assert scene.campaign.gate == "none"
    specs = [s for s in campaign_trials(scene, STACK, 0) if s.tube.name == "bent30"][::4]
    logs = tmp_path_factory.mktemp("free")
    outcomes = [run_sim_trial(s, scene, STACK, log_dir=logs) for s in specs]
    assert len(outcomes) == 6
    for o in outcomes:
        assert o.verdict is not None
        assert o.verdict.status != "ok", (o.spec.trial_id, o.true_motion)
