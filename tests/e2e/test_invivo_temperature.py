"""A lung trial as the sensor enters the body (issue 42): 22 -> 37 degC during the trial, each
grating's own thermal shift; every grating compensated with its calibrated ratio, the trial
reads as it does at room temperature; compensated with one coefficient for all, it is not ok."""

from __future__ import annotations

import dataclasses

import pytest

from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.config.schema import StackConfig
from palpate.simulation.trial import TrialOutcome
from tests.e2e.test_breath_hold import run_one

SCENE = load(SceneConfig, resolve("scenes/invivo/temperature.yaml"))
STACK = load_stack(SCENE.robot)


def trial(stack: StackConfig, tmp_path_factory: pytest.TempPathFactory) -> TrialOutcome:
    """F1: 10 kPa, 10 mm, through the 15 deg tube, downward."""
    return run_one(SCENE, stack, "F1", tmp_path_factory)


def test_every_grating_compensated_with_its_ratio(
    tmp_path_factory: pytest.TempPathFactory,
) -> None:
    assert SCENE.fidelity.temperature is not None
    assert SCENE.fidelity.temperature.step_degc == 15.0
    outcome = trial(STACK, tmp_path_factory)
    assert outcome.state == "done", outcome.reason
    assert outcome.verdict is not None
    assert outcome.verdict.status == "ok", outcome.verdict.reasons
    fit = outcome.joint
    assert fit is not None
    assert fit.modulus == pytest.approx(10e3, rel=0.05)
    room = dataclasses.replace(
        SCENE, fidelity=dataclasses.replace(SCENE.fidelity, temperature=None)
    )
    twin = run_one(room, STACK, "F1", tmp_path_factory).joint
    assert twin is not None
    assert fit.covers(twin.modulus)  # it reads as the same trial at room temperature
    assert twin.covers(fit.modulus)


def test_one_coefficient_for_every_grating_is_not_ok(
    tmp_path_factory: pytest.TempPathFactory,
) -> None:
    """The beam's gratings read 4 pm/degC of its expansion beyond the reference: 60 pm, 140 ue
    left in the strains by the end of the step, which the verdict sees as a lateral load."""
    tip = dataclasses.replace(STACK.sensor.tip_grating, thermal_ratio=None)  # type: ignore[arg-type]
    plain = dataclasses.replace(
        STACK,
        fbg=dataclasses.replace(STACK.fbg, thermal_ratios=None),
        sensor=dataclasses.replace(STACK.sensor, tip_grating=tip),
    )
    outcome = trial(plain, tmp_path_factory)
    assert outcome.verdict is not None
    assert outcome.verdict.status != "ok"
    assert any("misaligned" in r for r in outcome.verdict.reasons), outcome.verdict.reasons
