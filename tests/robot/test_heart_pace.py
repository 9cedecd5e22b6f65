"""The machine with an ECG (issue 62): once the heart is seen to beat (frame status bit 7), a
trial in a breath hold indents at the plan's heart speed and makes the time in the approach, at
full speed to the heart margin before the expected surface; without an ECG, or without a breath
hold (free breathing moves the tissue more than the beat), the plan's speeds are kept. Beside
a beating heart buckling is judged in mid-diastole and the stage then stands through two quiet
windows."""

from __future__ import annotations

import math
from dataclasses import dataclass

import pytest

from palpate.robot.body import R_WAVES_LOST, BodyWatch
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


def test_beside_a_heart_a_stiff_sample_buckles_in_the_quiet_phase_and_the_stage_stands() -> None:
    """The tip touches just before the rig's strains cross the detector's threshold (a stiff
    sample: the systole buckles the beam before diastole has pressed the tissue): the machine
    passes the crossing by outside mid-diastole, takes it there, then holds the stage (no
    post-buckling travel) until two more quiet windows have ended."""
    rig = BeatingRig(VirtualClock(), holds=hold_from(3.0, 60.0), x_contact=11.9e-3)
    p = plan(gated=True)
    result = run_trial(rig, rig.clock, p, Guards(), ThresholdDetector())
    assert result.state is State.DONE, result.reason
    t_buckled, x_buckled = result.marks.t_buckling, result.marks.x_buckling
    assert t_buckled is not None
    assert x_buckled is not None
    start, end = p.heart_quiet
    assert start <= (t_buckled % PERIOD) / PERIOD <= end
    over = [u for s, u, e in result.record if s == "indenting" and math.hypot(*e) > 50e-6]
    assert over
    assert over[0] < x_buckled - 5 * rig.tick * p.heart_speed  # passed by outside the window
    held = [u for s, u, _ in result.record if s == State.BUCKLED.value]
    assert max(held) - x_buckled < 2 * p.position_tolerance + rig.tick * p.heart_speed
    retract = next(tr for tr in result.transitions if tr.target is State.RETRACTING)
    ends = [k * PERIOD + end * PERIOD for k in range(int(retract.t / PERIOD) + 1)]
    assert sum(t_buckled < e < retract.t for e in ends) >= p.heart_windows


def test_beside_a_heart_a_soft_sample_ends_where_the_beam_buckles() -> None:
    """Touched 2 mm before buckling (a soft sample): the quiet windows in contact are many
    before the strains cross the threshold, and the machine takes the first crossing."""
    rig = BeatingRig(VirtualClock(), holds=hold_from(3.0, 60.0))
    result = run_trial(rig, rig.clock, plan(gated=True), Guards(), ThresholdDetector())
    assert result.state is State.DONE, result.reason
    over = [(s, u) for s, u, e in result.record if e and math.hypot(*e) > 50e-6]
    assert over[0] == ("buckled", result.marks.x_buckling)  # no indenting tick passed it by


def test_without_a_heart_the_post_buckling_travel_is_kept() -> None:
    rig = BeatingRig(VirtualClock(), holds=hold_from(3.0, 60.0), beats=False)
    p = plan(gated=True)
    result = run_trial(rig, rig.clock, p, Guards(), ThresholdDetector())
    assert result.state is State.DONE, result.reason
    assert result.marks.x_buckling is not None
    held = [u for s, u, _ in result.record if s == State.BUCKLED.value]
    assert max(held) == pytest.approx(result.marks.x_buckling + p.post_buckling_travel, abs=1e-5)


def test_the_watch_knows_the_quiet_phase_from_the_r_waves() -> None:
    body, p = BodyWatch(), plan(gated=True)
    assert body.quiet(0.5, p)  # no heart seen: every tick is quiet
    for t in (0.0, 1.0):
        body.see(Observation(t, 0.0, 0.0, (), False, beat=True))
        body.see(Observation(t + 0.02, 0.0, 0.0, (), False))
    assert body.period() == pytest.approx(1.0)
    assert body.quiet(1.8, p)
    assert not body.quiet(1.3, p)  # systole
    assert not body.quiet(1.95, p)  # the atria's kick
    assert body.quiet(1.0 + (R_WAVES_LOST + 0.1), p)  # the ECG lost: no phase to wait for
    late = BodyWatch()
    late.see(Observation(0.0, 0.0, 0.0, (), False, beat=True))
    assert not late.quiet(0.8, p)  # one R wave: the interval not yet known
    assert body.post_travel(p) == 0.0
    assert late.post_travel(plan()) == p.post_buckling_travel  # not gated: the plan's
