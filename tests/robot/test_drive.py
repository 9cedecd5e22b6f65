"""Roller-gear drive: joint <-> shaft round trips, slaving, coupling, limits, homing; units."""

from __future__ import annotations

import math
from collections.abc import Iterator

import pytest
from hypothesis import given
from hypothesis import strategies as st

from palpate.config.schema import DriveConfig, ServoBusConfig
from palpate.robot.drive import (
    INNER_ROLL,
    OUTER_ROLL,
    TRANSLATION,
    DriveController,
    JointLimitError,
    JointState,
    RollerGearDrive,
)
from palpate.robot.dynamixel import units
from palpate.robot.dynamixel.driver import DynamixelBus
from palpate.sim.clock import VirtualClock
from palpate.sim.dynamixel.bus import EmulatedBus

CFG = DriveConfig(
    outer_roll_ratio=2.0, inner_roll_ratio=1.5, lead_mm_per_rev=8.0, coupling_mm_per_rad=0.7
)
rolls = st.floats(math.radians(-200), math.radians(200))
translations = st.floats(0.0, 0.08)
shaft_angles = st.floats(-100.0, 100.0)


@given(rolls, translations, shaft_angles, shaft_angles, shaft_angles)
def test_joints_to_shafts_round_trip(
    roll: float, x: float, h0: float, h1: float, h2: float
) -> None:
    drive = RollerGearDrive(CFG, {OUTER_ROLL: h0, INNER_ROLL: h1, TRANSLATION: h2})
    q = drive.joints(drive.shafts(JointState(roll, x)))
    assert q.roll == pytest.approx(roll, abs=1e-9)
    assert q.translation == pytest.approx(x, abs=1e-12)


@given(rolls)
def test_inner_roll_is_slaved_and_coupling_is_compensated(roll: float) -> None:
    drive = RollerGearDrive(CFG)
    shafts = drive.shafts(JointState(roll, 0.0))
    assert shafts[OUTER_ROLL] == pytest.approx(2.0 * roll)
    assert shafts[INNER_ROLL] == pytest.approx(1.5 * roll)
    assert drive.twist(shafts) == pytest.approx(0.0, abs=1e-12)
    # the translation servo undoes the 0.7 mm/rad the roll would add
    expected = 2 * math.pi / 8e-3 * (-0.7e-3 * roll)
    assert shafts[TRANSLATION] == pytest.approx(expected, abs=1e-9)


def test_without_coupling_a_roll_leaves_the_translation_servo_alone() -> None:
    drive = RollerGearDrive(DriveConfig())
    assert drive.shafts(JointState(1.0, 0.02))[TRANSLATION] == pytest.approx(2 * math.pi)


def test_limits_are_enforced() -> None:
    drive = RollerGearDrive(DriveConfig())
    with pytest.raises(JointLimitError, match="translation"):
        drive.shafts(JointState(0.0, 0.081))
    with pytest.raises(JointLimitError, match="roll"):
        drive.shafts(JointState(math.radians(201), 0.0))


def test_homing_makes_the_present_shafts_the_home_pose() -> None:
    cfg = DriveConfig(home_translation_mm=10.0, home_roll_deg=30.0)
    drive = RollerGearDrive(cfg).homed({OUTER_ROLL: 5.0, INNER_ROLL: -2.0, TRANSLATION: 40.0})
    q = drive.joints({OUTER_ROLL: 5.0, INNER_ROLL: -2.0, TRANSLATION: 40.0})
    assert q.roll == pytest.approx(math.radians(30.0))
    assert q.translation == pytest.approx(0.010)


def test_profiles_follow_the_joint_limits() -> None:
    profiles = RollerGearDrive(CFG).profiles()
    assert profiles[OUTER_ROLL][0] == pytest.approx(math.radians(90.0) * 2.0)
    assert profiles[TRANSLATION][0] == pytest.approx(5e-3 / 8e-3 * 2 * math.pi)
    assert profiles[TRANSLATION][1] == pytest.approx(50e-3 / 8e-3 * 2 * math.pi)


@given(st.floats(-1500.0, 1500.0))
def test_ticks_round_trip_within_half_a_tick(angle: float) -> None:
    ticks = units.ticks_from_rad(angle)
    assert abs(units.rad_from_ticks(ticks) - angle) <= math.pi / 4096 + 1e-12


@given(st.integers(-(2**31), 2**31 - 1))
def test_signed_unsigned_round_trip(value: int) -> None:
    raw = units.to_unsigned(value, 4)
    assert 0 <= raw < 2**32
    assert units.to_signed(raw, 4) == value


def test_unit_conversions_reject_bad_values() -> None:
    with pytest.raises(ValueError, match="beyond"):
        units.ticks_from_rad(300 * 2 * math.pi)
    with pytest.raises(ValueError, match="finite"):
        units.ticks_from_rad(math.nan)
    with pytest.raises(ValueError, match="> 0"):
        units.velocity_units_from_rad_s(0.0)
    with pytest.raises(ValueError, match="fit"):
        units.to_unsigned(2**32, 4)


@pytest.fixture
def controller() -> Iterator[tuple[DriveController, EmulatedBus, VirtualClock]]:
    clock = VirtualClock()
    bus_cfg = ServoBusConfig(max_goal_step_deg=360.0, timeout_ms=2000.0)  # generous: no race
    with EmulatedBus.from_config(bus_cfg, clock=clock) as emulator:
        motors = DynamixelBus.from_config(bus_cfg, port=emulator.port)
        with DriveController(motors, DriveConfig(coupling_mm_per_rad=0.5)) as ctl:
            yield ctl, emulator, clock


def test_controller_drives_the_emulated_robot(
    controller: tuple[DriveController, EmulatedBus, VirtualClock],
) -> None:
    ctl, emulator, clock = controller
    target = JointState(math.radians(20.0), 0.004)
    goal = ctl.command(target)
    assert goal.roll == pytest.approx(target.roll, abs=1e-3)
    for _ in range(20):
        clock.advance(0.5)
        ctl.command(target)
    q, state = ctl.read()
    assert q.roll == pytest.approx(target.roll, abs=2e-3)
    assert q.translation == pytest.approx(target.translation, abs=1e-5)
    assert set(state) == {OUTER_ROLL, INNER_ROLL, TRANSLATION}
    assert emulator.servo(1).position_ticks == emulator.servo(2).position_ticks  # slaved
    assert emulator.servo(3).item("Profile_Velocity") > 0


def test_controller_close_releases_torque(
    controller: tuple[DriveController, EmulatedBus, VirtualClock],
) -> None:
    ctl, emulator, _ = controller
    assert all(s.torque_enabled for s in emulator.servos)
    ctl.close()
    assert not any(s.torque_enabled for s in emulator.servos)
