"""The breath-hold gate in the indentation machine (issue 42): a gated trial waits at the
stand-off for a breath hold that has just begun, indents within it; a hold that ends before the
indentation does retracts it and the machine waits for the next (issue 62), up to the plan's
retries, after which the trial ends with no estimate (not a fault)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import pytest

from palpate.estimation.verdict import HOLDS_RAN_OUT
from palpate.robot.indentation import Guards, Observation, State, TrialPlan
from palpate.robot.trial.run import run_trial
from palpate.sim.clock import VirtualClock
from tests.robot.test_indentation import ScriptedRig, ThresholdDetector, plan, states


@dataclass
class GatedRig(ScriptedRig):
    """The scripted rig, with the ventilator's gate open while ``holds(t)``."""

    holds: Callable[[float], bool] = lambda t: False

    def observe(self, t: float) -> Observation:
        obs = super().observe(t)
        return Observation(**{**obs.__dict__, "gate": self.holds(t)})


def hold_from(start: float, length: float, cycle: float = 100.0) -> Callable[[float], bool]:
    return lambda t: start <= t % cycle < start + length


def gated(rig: GatedRig, **kw: float) -> object:
    return run_trial(rig, rig.clock, plan(gated=True, **kw), Guards(), ThresholdDetector())


def test_the_trial_waits_for_a_hold_and_indents_within_it() -> None:
    rig = GatedRig(VirtualClock(), holds=hold_from(12.0, 20.0))
    result = gated(rig)
    assert result.state is State.DONE, result.reason
    assert states(result.transitions)[:4] == ["homing", "positioning", "waiting", "approach"]
    approach = next(tr for tr in result.transitions if tr.target is State.APPROACH)
    assert approach.t == pytest.approx(12.0, abs=0.01)  # the hold's first tick
    assert approach.reason == "breath hold"
    assert result.marks.t_contact is not None
    assert 12.0 < result.marks.t_contact < 32.0


def test_a_hold_under_way_at_the_stand_off_is_waited_out() -> None:
    """Its end is not known: the machine waits for the next hold to begin."""
    rig = GatedRig(VirtualClock(), holds=hold_from(0.0, 30.0, cycle=40.0))
    result = gated(rig)
    assert result.state is State.DONE, result.reason
    approach = next(tr for tr in result.transitions if tr.target is State.APPROACH)
    assert approach.t == pytest.approx(40.0, abs=0.01)


def test_a_hold_that_ends_during_the_indentation_is_retried_in_the_next() -> None:
    """A 2.5 s hold is too short for the trial; the next, 20 s long, holds all of it."""
    rig = GatedRig(VirtualClock(), holds=lambda t: 5.0 <= t < 7.5 or 25.0 <= t < 45.0)
    result = gated(rig)
    assert result.state is State.DONE, result.reason
    assert result.reason == "completed"
    reasons = [tr.reason for tr in result.transitions]
    assert any(r.startswith("the breath hold ended during ") for r in reasons)
    assert "to the next breath hold" in reasons
    assert states(result.transitions).count("waiting") == 2
    assert result.marks.t_contact is not None
    assert result.marks.t_contact > 25.0
    assert result.marks.x_buckling is not None


def test_holds_that_keep_ending_first_end_the_trial_with_no_estimate() -> None:
    """Every hold 4 s, the tissue never buckles the beam: three holds tried, then DONE, retracted,
    with the reason the verdict reads as no estimate; never a fault."""
    rig = GatedRig(VirtualClock(), holds=hold_from(5.0, 4.0, cycle=20.0), x_buckle=1.0)
    result = gated(rig)
    assert result.state is State.DONE
    assert result.reason.startswith(HOLDS_RAN_OUT)
    assert states(result.transitions).count("waiting") == 3  # 1 + TrialPlan.hold_retries
    assert rig.advance == pytest.approx(0.0, abs=1e-5)  # retracted home
    assert rig.torque


def test_an_ungated_plan_goes_without_waiting() -> None:
    rig = GatedRig(VirtualClock(), holds=lambda t: False)
    result = run_trial(rig, rig.clock, plan(), Guards(), ThresholdDetector())
    assert result.state is State.DONE, result.reason
    assert "waiting" not in states(result.transitions)
    assert TrialPlan.gated is False


@dataclass
class BreathingRig(GatedRig):
    """The gated rig whose tissue comes to the waiting tip from ``reach_at`` (s) on: a breath
    larger than the stand-off."""

    reach_at: float = 5.0

    def observe(self, t: float) -> Observation:
        obs = super().observe(t)
        return Observation(**{**obs.__dict__, "contact": obs.contact or t >= self.reach_at})


def test_tissue_that_reaches_the_waiting_tip_faults_and_says_to_raise_the_stand_off() -> None:
    rig = BreathingRig(VirtualClock(), holds=hold_from(30.0, 20.0))
    result = gated(rig)
    assert result.state is State.FAULT
    assert result.reason.startswith("unexpected contact during waiting")
    assert result.reason.endswith("raise campaign.standoff_mm past the breath's excursion")
    assert rig.advance == pytest.approx(0.0, abs=1e-5)  # retracted home


def test_a_contact_while_positioning_names_no_stand_off() -> None:
    rig = GatedRig(VirtualClock(), x_contact=5e-3)
    result = gated(rig)
    assert result.state is State.FAULT
    assert "standoff" not in result.reason
