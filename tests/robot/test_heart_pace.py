"""The machine with an ECG (issue 62): once the heart is seen to beat (frame status bit 7), a
trial in a breath hold indents at the plan's heart speed and makes the time in the approach, at
full speed to the heart margin before the expected surface; without an ECG, or without a breath
hold (free breathing moves the tissue more than the beat), the plan's speeds are kept."""

from __future__ import annotations

from dataclasses import dataclass

import pytest

from palpate.robot.body import BodyWatch
from palpate.robot.indentation import Guards, Observation, State
from palpate.robot.trial.run import run_trial
from palpate.sim.clock import VirtualClock
from tests.robot.test_breath_gate import GatedRig, hold_from
from tests.robot.test_indentation import ThresholdDetector, plan

PERIOD = 0.9


@dataclass
class BeatingRig(GatedRig):
    """The gated rig with an ECG's sync pulse for 20 ms at each R wave (``beats``)."""

    beats: bool = True

    def observe(self, t: float) -> Observation:
        obs = super().observe(t)
        return Observation(**{**obs.__dict__, "beat": self.beats and t % PERIOD < 0.02})


def speeds_in(result: object, rig: BeatingRig, state: State) -> set[float]:
    """The commanded speeds on the ticks the machine spent in ``state``."""
    rows = result.record  # type: ignore[attr-defined]
    return {c.speed for (s, _, _), c in zip(rows, rig.commands, strict=False) if s == state.value}


@pytest.mark.parametrize(("beats", "gated"), [(True, True), (False, True), (True, False)])
def test_the_heart_slows_the_indentation_and_quickens_the_approach(
    beats: bool, gated: bool
) -> None:
    rig = BeatingRig(VirtualClock(), holds=hold_from(3.0, 60.0), beats=beats)
    p = plan(gated=gated)
    result = run_trial(rig, rig.clock, p, Guards(), ThresholdDetector())
    assert result.state is State.DONE, result.reason
    indent = speeds_in(result, rig, State.INDENTING)
    approach = speeds_in(result, rig, State.APPROACH)
    if beats and gated:
        assert indent == {p.heart_speed}
        assert p.fast_speed in approach
        assert p.approach_speed in approach
    else:
        assert indent == {p.indent_speed}
        assert approach == {p.approach_speed}


def test_the_watch_counts_a_hold_only_as_it_begins() -> None:
    body = BodyWatch()
    at = lambda t, gate: Observation(t, 0.0, 0.0, (), False, gate=gate)  # noqa: E731
    body.see(at(0.0, True))  # under way at the start: its beginning not seen
    assert not body.hold_began(at(0.0, True), 1.0)
    body.see(at(1.0, False))
    body.see(at(2.0, True))
    assert body.hold_began(at(2.5, True), 1.0)
    assert not body.hold_began(at(3.5, True), 1.0)  # began 1.5 s before: its end not known
    assert not body.beating
    body.see(Observation(4.0, 0.0, 0.0, (), False, beat=True))
    assert body.beating
