"""The straight tube on tilted samples (issue 25): probing cannot measure a normal, so no trial
is ``ok``; a slipping tip is named misaligned with the angle its path shows, a sticking one
unverified."""

from __future__ import annotations

import math

import pytest

from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.simulation.trial import TrialSpec, run_sim_trial

STACK = load_stack()
SCENE = load(SceneConfig, resolve("scenes/oblique/straight.yaml"))


def spec(sample: str) -> TrialSpec:
    modulus = next(s.modulus for s in SCENE.samples if s.name == sample)
    return TrialSpec(
        f"{sample}-straight", "robot", sample, modulus, 0.45,
        STACK.tube("straight"), "downward", 0.0,
        42e-3, 2,
    )  # fmt: skip


def test_a_sticking_straight_tube_on_a_tilted_sample_is_unverified_not_ok() -> None:
    out = run_sim_trial(spec("S8-t12-stick"), SCENE, STACK)
    assert out.state == "done", out.reason
    assert out.true_misalignment is not None
    assert math.degrees(out.true_misalignment) > 2.0  # the world's: beyond the tolerance
    assert out.probe is not None
    assert out.probe.normal is None  # no normal measured
    assert out.verdict is not None
    assert out.verdict.status == "suspect"
    assert any(r.startswith("orientation unverified") for r in out.verdict.reasons)
    assert out.lean is not None
    assert out.lean.success
    assert not out.lean.lateral
    assert not out.lean.measured  # a held tip leaves no path to read the angle from
    assert "misalignment" not in out.lean.record()


@pytest.mark.parametrize("sample", ["S8-t8-mu005", "S8-t17-mu02"])
def test_a_slipping_straight_tube_is_suspect_with_the_angle_measured_from_its_path(
    sample: str,
) -> None:
    """The world's slipping contact (the tip slides 8 or 17 deg off square, friction 0.05 or
    0.2): the misalignment read from the strains and the stage's advance holds the world's
    angle within three of its sigmas, and the verdict names it."""
    out = run_sim_trial(spec(sample), SCENE, STACK)
    assert out.verdict is not None
    assert out.verdict.status == "suspect"
    assert out.lean is not None
    assert out.lean.lateral
    assert out.lean.measured
    assert out.true_misalignment is not None
    error = abs(out.lean.misalignment - out.true_misalignment)
    assert error < 3.0 * out.lean.misalignment_sigma
    assert math.degrees(error) < 2.0
    shown = f"misalignment {math.degrees(out.lean.misalignment):.1f} +- "
    assert any(r.startswith(f"misaligned: {shown}") for r in out.verdict.reasons)
    lean = out.as_dict()["strain_lean"]
    assert lean["lateral"] is True
    assert lean["misalignment_deg"] == pytest.approx(math.degrees(out.lean.misalignment))


OFFSET = load(SceneConfig, resolve("scenes/oblique/offset.yaml"))


def test_a_sample_that_is_not_there_ends_unreachable_with_torque_on() -> None:
    """The first touch finds nothing within the window: a geometric answer (unreachable, the
    reason named), not a fault and not a state timeout; well within probing's budget."""
    modulus = next(s.modulus for s in OFFSET.samples if s.name == "S8-absent")
    spec = TrialSpec(
        "absent",
        "robot",
        "S8-absent",
        modulus,
        0.45,
        STACK.tube("bent30"),
        "downward",
        0.0,
        42e-3,
        2,
    )
    out = run_sim_trial(spec, OFFSET, STACK)
    assert out.state == "unreachable", out.reason
    assert "no surface within" in out.reason
    assert "timeout" not in out.reason
    assert out.sim_time < 60.0
    assert out.verdict is not None
    assert out.verdict.status != "ok"


def test_probings_budget_comes_from_the_drive_and_stays_below_the_state_timeout() -> None:
    from palpate.robot.indentation import STATE_TIMEOUT
    from palpate.robot.probing import probe_budget

    offsets = (0.125, 0.5, -0.5)
    slow = probe_budget(offsets, 3e-3, 2.5e-3, 5e-3, math.radians(90), 0.4)
    fast = probe_budget(offsets, 3e-3, 5e-3, 10e-3, math.radians(180), 0.4)
    assert 0 < fast < slow < STATE_TIMEOUT


def test_a_displaced_sample_is_found_and_indented_where_it_is() -> None:
    """5 mm beyond the plan (past the approach window): the first touch looks past it, and the
    straight tube approaches where its touch found the surface."""
    modulus = next(s.modulus for s in OFFSET.samples if s.name == "S8-off5-t0")
    spec = TrialSpec(
        "off5",
        "robot",
        "S8-off5-t0",
        modulus,
        0.45,
        STACK.tube("straight"),
        "downward",
        0.0,
        42e-3,
        2,
    )
    out = run_sim_trial(spec, OFFSET, STACK)
    assert out.state == "done", out.reason
    assert out.joint is not None
    assert out.joint.modulus is not None
    assert abs(out.joint.modulus / out.spec.modulus - 1) < 0.05
