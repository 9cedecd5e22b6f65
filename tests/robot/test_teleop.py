"""The teleoperation model: jogs, limits, guards, emergency stop, targets, screen text."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import pytest

from palpate.commands.teleop_screen import render
from palpate.config.schema import DEFAULT_TUBES, DriveConfig
from palpate.config.targets import load_targets, save_target
from palpate.estimation.detect.buckling import NormThreshold
from palpate.robot.indentation import (
    Guards,
    IndentationMachine,
    Observation,
    State,
    TrialPlan,
    limit_violation,
)
from palpate.robot.teleop import Effect, JogSettings, Teleop

DRIVE = DriveConfig()  # translation 0..80 mm, roll -200..200 deg, home 0
GUARDS = Guards(max_travel_past_contact=2.5e-3, strain_limit=5e-3, stream_timeout=0.1)
MM = 1e-3


def make(drive: DriveConfig = DRIVE, tube_name: str | None = None) -> Teleop:
    return Teleop(drive, DEFAULT_TUBES, GUARDS, NormThreshold(300e-6), tube_name=tube_name)


def obs(
    advance_mm: float = 0.0,
    strains: tuple[float, ...] = (0.0, 0.0, 0.0),
    *,
    roll_deg: float = 0.0,
    contact: bool = False,
    stream_age: float = 0.0,
    servo_fault: str | None = None,
    t: float = 0.0,
) -> Observation:
    return Observation(
        t=t,
        advance=advance_mm * MM,
        roll=math.radians(roll_deg),
        strains=strains,
        contact=contact,
        stream_age=stream_age,
        servo_fault=servo_fault,
    )


def test_one_press_moves_the_goal_one_step_at_the_jog_speed() -> None:
    m = make()
    m.step(obs(10.0))
    assert m.press("up") is None
    cmd = m.step(obs(10.0))
    assert cmd.advance == pytest.approx(11.0 * MM)  # default step 1 mm
    assert cmd.speed == pytest.approx(2 * MM)  # default speed 2 mm/s
    assert m.state is State.POSITIONING
    m.press("down")
    assert m.step(obs(10.0)).advance == pytest.approx(10.0 * MM)
    assert m.state is State.IDLE


def test_queued_presses_never_run_away_from_the_stage() -> None:
    m = make()
    m.step(obs(10.0))
    for _ in range(50):  # a held key's auto-repeat while the stage has not moved yet
        m.press("k")
    cmd = m.step(obs(10.0))
    tol = JogSettings().position_tolerance
    assert 10.0 * MM < cmd.advance <= 11.0 * MM + tol
    for _ in range(50):
        m.press("h")
    roll_goal = m.step(obs(10.0)).roll
    assert 0 > roll_goal >= -math.radians(10.0) - JogSettings().roll_tolerance


def test_jogs_stop_at_the_drive_limits() -> None:
    m = make()
    m.step(obs(0.0))
    m.press("down")
    assert m.step(obs(0.0)).advance == 0.0
    assert "translation limit" in m.message
    m = make()
    m.step(obs(79.6))
    m.press("up")
    assert m.step(obs(79.6)).advance == pytest.approx(80.0 * MM)
    m = make()
    m.step(obs(0.0, roll_deg=195.0))
    m.press("right")
    assert m.step(obs(0.0, roll_deg=195.0)).roll == pytest.approx(math.radians(200.0))
    assert "roll limit" in m.message


def test_step_and_speed_levels_are_bounded_and_speed_capped_by_the_drive() -> None:
    m = make()
    for _ in range(10):
        m.press("+")
        m.press("]")
    assert m.step_size == JogSettings().steps[-1]
    assert m.speed == pytest.approx(DRIVE.max_speed)
    for _ in range(10):
        m.press("-")
        m.press("[")
    assert m.step_size == JogSettings().steps[0]
    assert m.speed == pytest.approx(JogSettings().speeds[0])
    slow = make(drive=dataclasses.replace(DRIVE, max_speed_mm_per_s=1.0))
    for _ in range(5):
        slow.press("]")
    assert slow.speed == pytest.approx(1.0 * MM)


def test_roll_is_blocked_in_contact() -> None:
    m = make()
    m.step(obs(42.0, contact=True))
    m.press("right")
    assert m.step(obs(42.0, contact=True)).roll == 0.0
    assert "roll is blocked" in m.message


def test_a_jog_stops_short_of_the_travel_past_contact_limit() -> None:
    m = make()
    m.step(obs(42.0, contact=True))
    assert m.x_contact == pytest.approx(42.0 * MM)
    m.press("+")  # 5 mm steps
    m.press("up")
    cmd = m.step(obs(42.0, contact=True))
    limit = 42.0 * MM + GUARDS.max_travel_past_contact
    assert cmd.advance < limit
    assert cmd.advance == pytest.approx(limit - JogSettings().travel_margin)
    assert "travel-past-contact limit" in m.message


def test_a_jog_begun_before_contact_stops_short_of_the_travel_limit() -> None:
    m = make()
    m.step(obs(40.0))
    m.press("+")
    m.press("up")  # 5 mm on: 45 mm, beyond 42 + 2.5 once the tip touches at 42
    assert m.step(obs(41.0)).advance == pytest.approx(45.0 * MM)
    cmd = m.step(obs(42.0, contact=True))
    assert cmd.advance == pytest.approx(44.5 * MM - JogSettings().travel_margin)
    assert "travel limit" in m.message
    assert m.state is State.POSITIONING


@pytest.mark.parametrize(
    ("first", "later", "reason"),
    [
        (obs(42.0, contact=True), obs(42.5, (6e-3, 0, 0), contact=True), "fiber strain"),
        (obs(42.0, contact=True), obs(44.6, contact=True), "travel past contact"),
        (obs(42.0, contact=True), obs(42.1, contact=True, stream_age=1.5), "FBG stream lost"),
    ],
)
def test_a_guard_stops_and_retracts_then_leaves_torque_off(
    first: Observation, later: Observation, reason: str
) -> None:
    m = make()
    m.step(first)
    cmd = m.step(later)
    assert m.state is State.RETRACTING
    assert m.fault is not None
    assert reason in m.fault
    assert cmd.advance == m.home
    assert cmd.speed == pytest.approx(DRIVE.max_speed)
    m.press("up")  # jogs are refused until re-armed
    assert m.step(obs(20.0)).advance == m.home
    cmd = m.step(obs(0.0))
    assert m.state is State.FAULT
    assert cmd.torque is False
    assert m.press("r") == Effect("recover")
    assert m.state is State.IDLE
    assert m.fault is None


def test_teleop_and_the_trial_state_machine_trip_on_the_same_limit() -> None:
    """The guards are the trial's: one function, the same reason, the same observation."""
    hot = obs(42.2, (5.5e-3, 0.0, 0.0), contact=True, t=1.0)
    m = make()
    m.step(obs(42.0, contact=True))
    m.step(hot)
    machine = IndentationMachine(
        TrialPlan(roll=0.0, contact_advance=42e-3), GUARDS, NormThreshold(1)
    )
    machine.marks.x_contact = 42.0 * MM
    machine.state = State.INDENTING
    machine.step(hot)
    assert m.fault == machine.marks.reason == limit_violation(GUARDS, hot, 42.0 * MM)


def test_emergency_stop_retracts_holds_and_rearms() -> None:
    m = make()
    m.step(obs(30.0))
    m.press("up")
    m.step(obs(30.2))
    m.press(" ")
    cmd = m.step(obs(30.4))
    assert m.state is State.RETRACTING
    assert cmd.advance == m.home == 0.0
    assert "EMERGENCY STOP" in m.message
    cmd = m.step(obs(0.0))
    assert m.state is State.ABORTED
    assert cmd.torque is True  # holds the retracted pose
    assert cmd.advance == 0.0
    m.press("up")
    assert m.step(obs(0.0)).advance == 0.0
    assert "re-arm" in m.message
    assert m.press("r") is None  # torque is still on: nothing to recover
    m.step(obs(0.0))
    m.press("up")
    assert m.step(obs(0.0)).advance == pytest.approx(1.0 * MM)


def test_a_servo_fault_retracts_and_a_second_one_releases_torque() -> None:
    m = make()
    m.step(obs(30.0))
    m.step(obs(30.0, servo_fault="servo 3: hardware error: Overload"))
    assert m.state is State.RETRACTING
    cmd = m.step(obs(29.0, servo_fault="servo 3: hardware error: Overload"))
    assert m.state is State.FAULT
    assert cmd.torque is False
    assert m.fault is not None
    assert "while retracting" in m.fault
    m.press(" ")  # nothing to stop: torque is already off
    assert m.state is State.FAULT


def test_advancing_without_fbg_frames_is_refused() -> None:
    m = make()
    m.step(obs(10.0, stream_age=1.0))
    m.press("up")
    assert m.step(obs(10.0, stream_age=1.0)).advance == pytest.approx(10.0 * MM)
    assert "no FBG frames" in m.message
    m.press("down")  # retracting stays possible
    assert m.step(obs(10.0, stream_age=1.0)).advance == pytest.approx(9.0 * MM)


def test_buckling_flag_follows_the_detector_in_contact_only() -> None:
    m = make()
    m.step(obs(42.0, (400e-6, 0.0, 0.0)))
    assert not m.buckled  # no contact: strains alone do not say buckled
    m.step(obs(42.1, (400e-6, 0.0, 0.0), contact=True))
    assert m.buckled
    m.step(obs(41.0))
    assert not m.buckled


def test_tube_changes_only_with_the_sensor_inside_the_tube() -> None:
    m = make()
    m.step(obs(12.0))
    assert m.press("t") is None
    assert m.tube.name == "straight"
    assert "retract the sensor" in m.message
    m = make()
    m.step(obs(0.0))
    assert m.press("t") == Effect("tube", "bent15")
    assert m.press("T") == Effect("tube", "straight")
    assert m.press("T") == Effect("tube", "bent50")


def test_saving_a_target_writes_the_measured_pose(tmp_path: Path) -> None:
    m = make(tube_name="bent30")
    m.step(obs(40.25, roll_deg=90.0))
    m.press("up")  # the goal moves; the measured pose is what gets saved
    assert m.press("s") is None
    assert m.prompt == ""
    for ch in "soft/side":  # '/' is not allowed in a name and is dropped
        m.press(ch)
    m.press("backspace")
    effect = m.press("enter")
    assert effect == Effect("save", "softsid")
    target = m.target(effect.value, note="n")
    path = tmp_path / "targets.yaml"
    save_target(path, target)
    stored = load_targets(path).get("softsid")
    assert stored.tube == "bent30"
    assert stored.roll_deg == pytest.approx(90.0)
    assert stored.translation_mm == pytest.approx(40.25)


def test_the_prompt_takes_keys_and_escape_cancels_but_space_still_stops() -> None:
    m = make()
    m.step(obs(5.0))
    m.press("s")
    m.press("q")  # a letter of the name, not quit
    assert m.prompt == "q"
    m.press("escape")
    assert m.prompt is None
    m.press("s")
    assert m.press("enter") == Effect("save", m.suggested_name())
    m.press("s")
    m.press(" ")
    assert m.prompt is None
    assert m.state is State.RETRACTING


def test_render_shows_the_pose_strains_flags_and_fits_the_width() -> None:
    m = make(tube_name="bent30")
    m.step(obs(42.0, roll_deg=0.0, strains=(100e-6, -200e-6, 50e-6), contact=True))
    lines = render(m.view(), width=72)
    text = "\n".join(lines)
    assert all(len(line) <= 72 for line in lines)
    assert "state      IDLE" in text
    assert "tube       bent30 (30 deg)" in text
    assert "advance       42.000 mm" in text
    assert "exposed       42.000 mm" in text
    assert "e1   +100.0  e2   -200.0  e3    +50.0 ue" in text
    assert "norm          229.1 ue" in text
    assert "contact    YES" in text
    # tangent of a 30 deg tube bending down at roll 0: (cos 30, 0, -sin 30)
    assert "tangent    x   +0.866  y   +0.000  z   -0.500" in text


def test_render_before_any_reading() -> None:
    text = "\n".join(render(make().view()))
    assert "advance            - mm" in text
    assert "tube tip   -" in text


def test_render_shows_a_tip_gratings_load_when_the_sensor_has_one() -> None:
    m = make(tube_name="bent30")
    m.step(dataclasses.replace(obs(42.0), tip_force=3.25e-3))
    assert "tip load      3.250 mN" in "\n".join(render(m.view()))
    m.step(obs(42.0))
    assert "tip load" not in "\n".join(render(m.view()))  # the paper's sensor has none
