"""The indentation state machine and the trial loop on a scripted one-axis rig.

The rig here is deliberately simple (a stage that moves at the commanded speed, contact at a
known advance, strains that grow after a known buckling advance) so that each guard can be
triggered on purpose and its transition checked. End-to-end trials on the simulator are in
tests/sim/.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest

from palpate.robot.indentation import (
    Command,
    Guards,
    IndentationMachine,
    Observation,
    State,
    Transition,
    TrialPlan,
)
from palpate.robot.records.log import TrialLogWriter, read_log
from palpate.robot.trial.run import end_record, run_trial
from palpate.sim.clock import VirtualClock


@dataclass
class ThresholdDetector:
    threshold: float = 50e-6

    def reset(self) -> None:
        pass

    def update(
        self, strains: tuple[float, ...], advance: float | None = None, load: float | None = None
    ) -> bool:
        return math.sqrt(sum(s * s for s in strains)) > self.threshold


@dataclass
class ScriptedRig:
    clock: VirtualClock
    tick: float = 2e-3  # s, the control period
    x_contact: float = 10e-3
    x_buckle: float = 10.3e-3
    advance: float = 3e-3
    roll: float = 0.0
    fault_at: float | None = None  # advance where the servo reports a fault
    fault_clears: bool = True
    stream_dies_at: float | None = None  # advance past which no frame comes again
    stream_gap: tuple[float, float] | None = None  # times (s) between which no frame comes
    strain_gain: float = 0.02  # strain per metre past buckling
    glitch_at: float | None = None  # advance where one tick reads a contact (the zero's noise)
    slip: tuple[float, float] | None = None  # (advance, jump m): the stage slips once past it
    torque: bool = True
    commands: list[Command] = field(default_factory=list)
    _goal: Command | None = None
    _last: float = 0.0
    _fault: bool = False
    released: int = 0
    _died: float | None = None  # when the stream died

    def observe(self, t: float) -> Observation:
        dt = t - self._last
        self._last = t
        if self._goal is not None and self.torque and not self._fault:
            step = self._goal.speed * dt
            self.advance += max(-step, min(step, self._goal.advance - self.advance))
            self.roll = self._goal.roll
        if self.slip is not None and self.advance >= self.slip[0]:
            self.advance, self.slip = self.advance + self.slip[1], None
        if self.fault_at is not None and self.advance >= self.fault_at and not self._fault:
            self._fault = True
            self.fault_at = None
        past = max(0.0, self.advance - self.x_buckle)
        strains = (self.strain_gain * past, -self.strain_gain * past, 0.5 * self.strain_gain * past)
        age = 0.0
        if self.stream_dies_at is not None and self.advance >= self.stream_dies_at:
            self._died = t if self._died is None else self._died
            age = t - self._died + self.tick
        if self.stream_gap is not None and self.stream_gap[0] <= t < self.stream_gap[1]:
            age = t - self.stream_gap[0] + self.tick
        glitch = self.glitch_at is not None and self.advance >= self.glitch_at
        if glitch:
            self.glitch_at = None
        return Observation(
            t=t,
            advance=self.advance,
            roll=self.roll,
            strains=strains,
            contact=self.advance >= self.x_contact or glitch,
            stream_age=age,
            servo_fault="overload" if self._fault else None,
        )

    def command(self, cmd: Command) -> None:
        self.commands.append(cmd)
        self._goal = cmd
        self.torque = cmd.torque

    def recover(self) -> bool:
        if self.fault_clears:
            self._fault = False
        return self.fault_clears

    def release(self) -> None:
        self.released += 1
        self.torque = False


@dataclass
class ListLog:
    """A trial log in memory: the records written, in order."""

    records: list[dict[str, Any]] = field(default_factory=list)

    def write(self, record: dict[str, Any]) -> None:
        self.records.append(record)


def plan(**kw: float) -> TrialPlan:
    base: dict[str, float] = {"roll": 0.0, "contact_advance": 10e-3, "home_advance": 0.0}
    base.update(kw)
    return TrialPlan(**base)


def run(rig: ScriptedRig, p: TrialPlan | None = None, guards: Guards | None = None, log=None):  # type: ignore[no-untyped-def]
    return run_trial(rig, rig.clock, p or plan(), guards or Guards(), ThresholdDetector(), log)


def states(transitions: list[Transition]) -> list[str]:
    return [tr.target.value for tr in transitions]


def test_normal_trial_visits_every_state_in_order() -> None:
    rig = ScriptedRig(VirtualClock())
    result = run(rig)
    assert result.state is State.DONE, result.reason
    assert states(result.transitions) == [
        "homing", "positioning", "approach", "contact",
        "indenting", "buckled", "retracting", "done",
    ]  # fmt: skip
    assert result.marks.x_contact == pytest.approx(10e-3, abs=2e-6)
    # the detector fires once the strain norm passes 50 ue: 50e-6 / (0.02 * 1.146) past buckling
    assert result.marks.x_buckling is not None
    assert result.marks.x_buckling > rig.x_buckle
    assert rig.advance == pytest.approx(0.0, abs=1e-5)  # retracted home
    assert rig.released == 0  # a completed trial keeps torque


def test_fiber_strain_guard_stops_and_retracts() -> None:
    rig = ScriptedRig(VirtualClock(), strain_gain=40.0)  # strain explodes right after buckling
    result = run(rig, guards=Guards(strain_limit=1e-4))
    assert result.state is State.FAULT
    assert "fiber strain" in result.reason
    assert rig.advance == pytest.approx(0.0, abs=1e-5)
    assert rig.released == 1


def test_a_travel_window_used_up_without_buckling_is_an_answer_not_a_fault() -> None:
    """Tissue below the sensor's range: the stage indents to the window's end, short of the
    guard, and retracts; the trial ends DONE, its reason naming the window (the verdict then
    says the tissue is too soft, with the modulus it is below)."""
    rig = ScriptedRig(VirtualClock(), x_buckle=1.0)  # never buckles
    result = run(rig, guards=Guards(max_travel_past_contact=0.5e-3))
    assert result.state is State.DONE
    assert result.reason.startswith("no buckling: travel past contact reached the 0.50 mm limit")
    indent_goals = [c.advance for c in rig.commands if c.speed == TrialPlan.indent_speed]
    assert indent_goals
    assert max(indent_goals) < 10e-3 + 0.5e-3  # the window ends short of the guard
    assert rig.advance == pytest.approx(0.0, abs=1e-5)  # retracted home
    assert rig.torque


def test_the_travel_past_contact_guard_still_faults_a_stage_that_slips_past_it() -> None:
    rig = ScriptedRig(VirtualClock(), x_buckle=1.0, slip=(10.3e-3, 0.4e-3))
    result = run(rig, guards=Guards(max_travel_past_contact=0.5e-3))
    assert result.state is State.FAULT
    assert "travel past contact" in result.reason
    assert "over the limit" in result.reason


def test_the_post_buckling_record_stops_at_the_window() -> None:
    """Buckling just before the window's end: the post-buckling travel is cut at the window
    (it used to run the stage into the guard, a fault, on soft samples)."""
    rig = ScriptedRig(VirtualClock(), x_buckle=10.25e-3, strain_gain=2.0)
    result = run(rig, guards=Guards(max_travel_past_contact=0.5e-3))
    assert result.state is State.DONE, result.reason
    assert result.marks.x_buckling is not None
    assert result.marks.x_buckling + TrialPlan.post_buckling_travel > 10e-3 + 0.5e-3
    indent_goals = [c.advance for c in rig.commands if c.speed == TrialPlan.indent_speed]
    assert max(indent_goals) < 10e-3 + 0.5e-3


def test_no_contact_within_window_faults() -> None:
    rig = ScriptedRig(VirtualClock(), x_contact=1.0)
    result = run(rig, plan(approach_window=1e-3))
    assert result.state is State.FAULT
    assert "no contact" in result.reason


def test_unexpected_early_contact_faults() -> None:
    rig = ScriptedRig(VirtualClock(), x_contact=5e-3)  # the tissue is 5 mm closer than planned
    result = run(rig)
    assert result.state is State.FAULT
    assert "contact" in result.reason
    assert rig.advance == pytest.approx(0.0, abs=1e-5)


def test_a_contact_at_rest_that_goes_away_is_held_rezeroed_and_the_trial_goes_on() -> None:
    """A contact while positioning, 5 mm before any tissue, seen on one tick (the zero's noise
    or drift): the stage holds still, the zero is taken again at rest, and the trial completes
    (it was a fault that ended the campaign's exit code)."""
    rig = ScriptedRig(VirtualClock(), glitch_at=4e-3)
    result = run(rig)
    assert result.state is State.DONE, result.reason
    rezeros = [i for i, c in enumerate(rig.commands) if c.rezero]
    assert len(rezeros) == 1
    first = rezeros[0]
    held = rig.commands[first - 10 : first + 1]
    assert all(c.speed == 0.0 for c in held)  # held still for the settle ticks, then re-zeroed
    assert held[0].advance == pytest.approx(4e-3, abs=1e-4)


def test_a_contact_at_rest_seen_again_after_the_rezero_faults() -> None:
    rig = ScriptedRig(VirtualClock(), x_contact=5e-3)  # real: it stays after the re-zero
    result = run(rig)
    assert result.state is State.FAULT
    assert (
        result.reason
        == "unexpected contact during positioning (seen again after 1 re-zero(s) at rest)"
    )
    assert sum(c.rezero for c in rig.commands) == 1


def test_stream_loss_during_indentation_faults() -> None:
    rig = ScriptedRig(VirtualClock(), stream_dies_at=10.1e-3)
    result = run(rig)
    assert result.state is State.FAULT
    assert "FBG stream lost" in result.reason


def test_a_stale_stream_holds_the_motion_records_the_gap_and_resumes() -> None:
    first = run(ScriptedRig(VirtualClock()))
    start = next(tr.t for tr in first.transitions if tr.target is State.INDENTING)
    gap = (start + 0.01, start + 0.5)  # past the stale timeout, short of the lost one
    rig = ScriptedRig(VirtualClock(), stream_gap=gap)
    log = ListLog()
    result = run(rig, log=log)
    assert result.state is State.DONE, result.reason
    assert states(result.transitions) == states(first.transitions)
    [(t, duration, state)] = result.stream_gaps
    assert t == pytest.approx(gap[0], abs=2 * rig.tick)
    assert duration == pytest.approx(gap[1] - gap[0], abs=2 * rig.tick)
    assert state == "indenting"
    held = [i for i, t in enumerate(result.times) if gap[0] + Guards().stream_timeout < t < gap[1]]
    assert held
    assert all(math.isnan(result.record[i][1]) for i in held)  # no estimate reads stale strains
    goals = {rig.commands[i].advance for i in held}
    assert all(rig.commands[i].speed == 0.0 for i in held)  # the motion held
    assert len(goals) == 1
    [record] = [r for r in log.records if r["kind"] == "stream_gap"]
    assert record["state"] == "indenting"
    assert record["duration"] == pytest.approx(duration)


def test_a_stream_stale_past_the_lost_timeout_faults_after_holding() -> None:
    rig = ScriptedRig(VirtualClock(), stream_dies_at=10.1e-3)
    result = run(rig, guards=Guards(stream_timeout=0.1, stream_lost=0.4))
    assert result.state is State.FAULT
    assert "FBG stream lost" in result.reason
    died = next(t for t, (_, a, _) in zip(result.times, result.record, strict=True) if a > 10.1e-3)
    fault = next(tr.t for tr in result.transitions if tr.target is State.RETRACTING)
    assert fault - died == pytest.approx(0.4, abs=3 * rig.tick)


def test_servo_fault_recovers_and_retracts() -> None:
    rig = ScriptedRig(VirtualClock(), fault_at=10.1e-3)
    result = run(rig)
    assert result.state is State.FAULT
    assert "servo fault" in result.reason
    assert rig.advance == pytest.approx(0.0, abs=1e-5)  # retracted after the reboot
    assert rig.released == 1


def test_servo_fault_that_does_not_clear_stops_limp() -> None:
    rig = ScriptedRig(VirtualClock(), fault_at=10.1e-3, fault_clears=False)
    result = run(rig)
    assert result.state is State.FAULT
    assert "while retracting" in result.reason
    assert rig.released == 1
    assert rig.torque is False


def test_state_timeout() -> None:
    rig = ScriptedRig(VirtualClock())
    result = run(rig, plan(approach_speed=1e-6), Guards(state_timeout=5.0))
    assert result.state is State.FAULT
    assert "timeout in approach" in result.reason


def test_operator_abort_ends_aborted_and_retracted() -> None:
    clock = VirtualClock()
    machine = IndentationMachine(plan(), Guards(), ThresholdDetector())
    obs = Observation(t=0.0, advance=0.0, roll=0.0, strains=(0, 0, 0), contact=False)
    machine.step(obs)
    machine.abort(clock.now(), "key pressed")
    assert machine.state is State.RETRACTING
    cmd = machine.step(Observation(t=0.1, advance=0.0, roll=0.0, strains=(0, 0, 0), contact=False))
    assert machine.state is State.ABORTED
    assert cmd.torque is False


def test_machine_runs_one_trial_only() -> None:
    machine = IndentationMachine(plan(), Guards(), ThresholdDetector())
    machine.start(0.0)
    with pytest.raises(RuntimeError, match="one trial"):
        machine.start(1.0)


def test_log_keeps_every_record_and_reads_back(
    tmp_path: Path, log_header: dict[str, object]
) -> None:
    rig = ScriptedRig(VirtualClock())
    path = tmp_path / "trial.jsonl"
    with TrialLogWriter(path, {"trial": "t1", **log_header}) as log:
        result = run(rig, log=log)
        log.write(end_record(result))
    back = read_log(path)
    assert back.complete
    assert back.header["trial"] == "t1"
    assert sum(1 for _ in back.of_kind("sample")) == result.ticks
    assert [r["to"] for r in back.of_kind("transition")] == states(result.transitions)
    assert back.end is not None
    assert back.end["marks"]["x_contact"] == result.marks.x_contact


def test_truncated_log_is_reported(
    tmp_path: Path, log_header: dict[str, object], log_sample: dict[str, object]
) -> None:
    path = tmp_path / "trial.jsonl"
    with TrialLogWriter(path, {"trial": "t2", **log_header}) as log:
        log.write(log_sample)
    with path.open("a", encoding="utf-8") as fh:
        fh.write('{"kind": "sam')  # torn line, as after a kill
    back = read_log(path)
    assert not back.complete
    assert back.bad_lines == 1
    assert len(back.records) == 1


# -- the hold after buckling (a creep test) -------------------------------------------------------


@dataclass
class TimedFaultRig(ScriptedRig):
    """A rig whose servo or FBG stream fails at a time (s), whatever the advance."""

    servo_fault_t: float | None = None
    stream_dies_t: float | None = None

    def observe(self, t: float) -> Observation:
        obs = super().observe(t)
        if self.servo_fault_t is not None and t >= self.servo_fault_t:
            self.servo_fault_t = None  # one fault; recover() clears it
            self._fault = True
            return dataclasses.replace(obs, servo_fault="overload")
        if self.stream_dies_t is not None and t >= self.stream_dies_t:
            return dataclasses.replace(obs, stream_age=t - self.stream_dies_t + self.tick)
        return obs


def _hold_span(result) -> tuple[float, float]:  # type: ignore[no-untyped-def]
    start = next(tr.t for tr in result.transitions if tr.target is State.HOLDING)
    end = next(tr.t for tr in result.transitions if tr.source is State.HOLDING)
    return start, end


def test_a_hold_stands_still_for_its_length_then_completes() -> None:
    rig = ScriptedRig(VirtualClock())
    result = run(rig, plan(hold_time=1.5))
    assert result.state is State.DONE, result.reason
    assert states(result.transitions) == [
        "homing", "positioning", "approach", "contact",
        "indenting", "buckled", "holding", "retracting", "done",
    ]  # fmt: skip
    start, end = _hold_span(result)
    assert end - start == pytest.approx(1.5, abs=rig.tick)  # on the virtual clock
    held = [a for (s, a, _), t in zip(result.record, result.times, strict=True) if s == "holding"]
    assert len(held) == pytest.approx(1.5 / rig.tick, abs=2)
    assert max(held) - min(held) <= TrialPlan.position_tolerance  # it only settled on its goal
    assert result.times == sorted(result.times)
    assert len(result.times) == len(result.record)


def test_without_a_hold_the_states_are_unchanged() -> None:
    result = run(ScriptedRig(VirtualClock()), plan(hold_time=0.0))
    assert "holding" not in states(result.transitions)


def test_a_servo_fault_during_the_hold_retracts() -> None:
    clock = VirtualClock()
    rig = TimedFaultRig(clock)
    first = run(ScriptedRig(VirtualClock()), plan(hold_time=2.0))
    start, _ = _hold_span(first)
    rig.servo_fault_t = start + 0.5  # the same trial, faulted half a second into the hold
    result = run(rig, plan(hold_time=2.0))
    assert result.state is State.FAULT
    assert "servo fault" in result.reason
    assert states(result.transitions)[-3:] == ["holding", "retracting", "fault"]
    assert rig.advance == pytest.approx(0.0, abs=1e-5)  # pulled back after the reboot


def test_a_lost_stream_during_the_hold_faults() -> None:
    first = run(ScriptedRig(VirtualClock()), plan(hold_time=2.0))
    start, _ = _hold_span(first)
    rig = TimedFaultRig(VirtualClock(), stream_dies_t=start + 0.5)
    result = run(rig, plan(hold_time=2.0))
    assert result.state is State.FAULT
    assert "FBG stream lost" in result.reason


def test_a_hold_as_long_as_the_state_timeout_is_refused() -> None:
    with pytest.raises(ValueError, match="hold_time"):
        IndentationMachine(plan(hold_time=5.0), Guards(state_timeout=5.0), ThresholdDetector())
    with pytest.raises(ValueError, match="hold_time"):
        IndentationMachine(plan(hold_time=-1.0), Guards(), ThresholdDetector())
