"""The hold section of ``palpate bench`` and the scenes' speed sweep: what they run."""

from __future__ import annotations

import pytest

from benchmarks.hold import HOLDS_S, SCENES, hold_scene, scene_speeds
from palpate.campaigns.campaign import campaign_trials
from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.simulation.trial import trial_campaign

STACK = load_stack()


@pytest.mark.parametrize("name", SCENES)
def test_each_hold_scene_changes_only_the_hold_length_and_speed(name: str) -> None:
    base = load(SceneConfig, resolve(f"scenes/{name}.yaml"))
    assert base.campaign.hold_s > 0  # the shipped scenes hold
    robot = base.campaign.on_tubes
    speeds = base.campaign.speeds_mm_per_s()
    assert speeds == ((0.5,) if robot else (0.1, 0.5, 2.0))
    assert scene_speeds(base, quick=True) == ("0.5" if robot else "0.1, 2")  # the table's note
    for hold in HOLDS_S:
        scene = hold_scene(base, hold, quick=True)
        assert scene.campaign.hold_s == hold
        if robot:  # one tube, every orientation, the robot's exposed length
            assert scene.campaign.tubes == ("bent30",)
            assert scene.campaign.orientations == base.campaign.orientations
            assert scene.campaign.speeds_mm_per_s() == (0.5,)
        else:
            assert scene.campaign.exposed_lengths_mm == (46.0,)
            assert scene.campaign.speeds_mm_per_s() == (0.1, 2.0)
        assert scene.samples == base.samples
        assert scene.fidelity == base.fidelity


def test_a_speed_sweep_runs_each_trial_at_each_speed() -> None:
    scene = load(SceneConfig, resolve("scenes/viscoelastic/gels.yaml"))
    specs = campaign_trials(scene, STACK)
    assert len(specs) == len(scene.samples) * 3 * 3  # samples x lengths x speeds
    first = [s for s in specs if s.trial_id.startswith("G320-straight-downward-L42-")]
    assert [s.indent_speed for s in first] == pytest.approx([0.1e-3, 0.5e-3, 2e-3])
    assert [s.trial_id.rsplit("-", 1)[1] for s in first] == ["v0.1", "v0.5", "v2"]
    assert trial_campaign(first[2], scene).indent_speed_mm_per_s == pytest.approx(2.0)
    plain = load(SceneConfig, resolve("scenes/bench.yaml"))
    spec = campaign_trials(plain, STACK)[0]
    assert spec.indent_speed is None
    assert trial_campaign(spec, plain) == plain.campaign


def test_a_campaign_that_ramps_through_the_contact_approaches_at_the_indentation_speed() -> None:
    from palpate.robot.trial.setup import trial_plan

    scene = load(SceneConfig, resolve("scenes/viscoelastic/power-law.yaml"))
    assert scene.campaign.ramp_through_contact
    spec = campaign_trials(scene, STACK)[0]
    ramp = trial_plan(trial_campaign(spec, scene), STACK, roll=0.0, contact=0.01, home=0.0)
    assert ramp.approach_speed == pytest.approx(ramp.indent_speed) == pytest.approx(0.1e-3)
    plain = load(SceneConfig, resolve("scenes/bench.yaml")).campaign
    assert not plain.ramp_through_contact
    step = trial_plan(plain, STACK, roll=0.0, contact=0.01, home=0.0)
    assert step.approach_speed == pytest.approx(plain.approach_speed_mm_per_s * 1e-3)
    assert step.approach_speed > step.indent_speed
