"""The straight tube on tilted samples (issue 25): probing cannot measure a normal, so no trial
is ``ok``; a slipping tip is named misaligned from its strains, a sticking one unverified."""

from __future__ import annotations

import math

from config import load, load_stack, resolve
from config.scene import SceneConfig
from palpate.simtrial import TrialSpec, run_sim_trial

STACK = load_stack()
SCENE = load(SceneConfig, resolve("scenes/oblique/straight.yaml"))


def spec(sample: str) -> TrialSpec:
    modulus = next(s.modulus for s in SCENE.samples if s.name == sample)
    return TrialSpec(
        f"{sample}-straight", "robot", sample, modulus, 0.45, "straight", "downward", 0.0,
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


def test_a_slipping_straight_tube_is_named_misaligned_from_its_strains() -> None:
    out = run_sim_trial(spec("S8-t8-mu005"), SCENE, STACK)
    assert out.verdict is not None
    assert out.verdict.status == "suspect"
    assert out.lean is not None
    assert out.lean.lateral
    assert any(r.startswith("misaligned: the strains") for r in out.verdict.reasons)
    assert out.as_dict()["strain_lean"]["lateral"] is True
