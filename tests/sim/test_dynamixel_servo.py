"""The emulated servo's control table, access rules and motion, without a bus."""

from __future__ import annotations

import itertools
import math

import pytest

from palpate.sim.dynamixel.motion import profile_motion
from palpate.sim.dynamixel.servo import EmulatedServo
from palpate.wire import dynamixel as tables

GOAL = tables.X_SERIES_CONTROL_TABLE["Goal_Position"][0]
TICKS_PER_S_PER_UNIT = 0.229 * 4096 / 60
TICKS_PER_S2_PER_UNIT = 214.577 * 4096 / 3600


def _le(value: int, size: int) -> bytes:
    return (value & ((1 << (8 * size)) - 1)).to_bytes(size, "little")


def _servo(model: str = "XM430-W350", mode: int = 4) -> EmulatedServo:
    s = EmulatedServo(1, model)
    assert s.write(11, bytes([mode])) == 0
    assert s.write(64, b"\x01") == 0
    return s


@pytest.mark.parametrize(("model", "number"), [("XM430-W350", 1020), ("XL430-W250", 1060)])
def test_power_on_values(model: str, number: int) -> None:
    s = EmulatedServo(5, model)
    assert s.item("Model_Number") == number
    assert s.item("ID") == 5
    assert s.item("Operating_Mode") == 3
    assert s.item("Status_Return_Level") == 2
    assert s.item("Torque_Enable") == 0
    assert s.read(0, 2) == (0, _le(number, 2))


def test_eeprom_is_writable_only_with_torque_off() -> None:
    s = EmulatedServo()
    assert s.write(11, bytes([4])) == 0
    assert s.write(64, b"\x01") == 0
    assert s.write(11, bytes([3])) == tables.ERR_ACCESS
    assert s.item("Operating_Mode") == 4
    assert s.write(65, b"\x01") == 0  # RAM stays writable


def test_access_rules() -> None:
    s = EmulatedServo(model="XL430-W250")
    assert s.write(132, _le(5, 4)) == tables.ERR_ACCESS  # read-only
    assert s.write(38, _le(100, 2)) == tables.ERR_ACCESS  # the XL430 has no Current_Limit
    assert s.write(117, b"\x00") == tables.ERR_DATA_LENGTH  # part of Goal_Position
    assert s.write(68, b"\x03") == tables.ERR_DATA_RANGE  # Status_Return_Level 0..2
    assert s.write(11, b"\x00") == tables.ERR_DATA_RANGE  # no current mode on the XL430
    assert s.write(GOAL, _le(5000, 4)) == tables.ERR_DATA_LIMIT  # mode 3: 0..4095
    assert s.read(140, 10) == (tables.ERR_ACCESS, b"")  # beyond the table
    assert s.write(14, b"\x00") == tables.ERR_ACCESS  # a reserved address


def test_a_failed_write_changes_nothing() -> None:
    s = EmulatedServo()
    before = bytes(s.memory)
    assert s.write(64, b"\x01\x01\x00\x00\x03") == tables.ERR_DATA_RANGE  # SRL 3 in the run
    assert bytes(s.memory) == before


def test_nothing_moves_without_time() -> None:
    s = _servo()
    s.write(GOAL, _le(4000, 4))
    assert s.position_ticks == 0
    s.advance_to(0.0)
    assert s.position_ticks == 0


def test_trapezoid_profile_reaches_the_goal_in_the_expected_time() -> None:
    s = _servo()
    v_units, a_units = 100, 20
    s.write(108, _le(a_units, 4))
    s.write(112, _le(v_units, 4))
    distance = 8000
    s.write(GOAL, _le(distance, 4))
    vmax = v_units * TICKS_PER_S_PER_UNIT
    amax = a_units * TICKS_PER_S2_PER_UNIT
    t_total = distance / vmax + vmax / amax  # trapezoid: cruise + one ramp time
    peak = 0.0
    steps = 200
    for k in range(1, steps + 1):
        s.advance_to(k * 1.2 * t_total / steps)
        peak = max(peak, s.velocity_ticks_per_s)
        assert s.velocity_ticks_per_s >= 0
    assert s.position_ticks == distance
    assert peak == pytest.approx(vmax, rel=1e-3)
    # at half the ramp time the servo has covered a t^2 / 2
    s2 = _servo()
    s2.write(108, _le(a_units, 4))
    s2.write(112, _le(v_units, 4))
    s2.write(GOAL, _le(distance, 4))
    t_half_ramp = 0.5 * vmax / amax
    s2.advance_to(t_half_ramp)
    assert s2.position_ticks == pytest.approx(0.5 * amax * t_half_ramp**2, rel=0.02)
    s2.advance_to(t_total * 0.98)
    assert s2.item("Moving") == 1
    s2.advance_to(t_total * 1.02)
    assert s2.position_ticks == distance
    assert s2.item("Moving") == 0
    assert s2.item("Moving_Status") & 0x01  # in position


def test_without_a_profile_the_velocity_limit_bounds_the_speed() -> None:
    s = _servo()
    s.write(GOAL, _le(-100_000, 4))
    s.advance_to(1.0)
    expected = -200 * TICKS_PER_S_PER_UNIT  # XM430-W350 Velocity_Limit default 200
    assert s.position_ticks == pytest.approx(expected, abs=1)
    assert s.item("Present_Velocity") == -200


def test_velocity_mode_turns_at_the_goal_velocity() -> None:
    s = _servo(mode=1)
    s.write(104, _le(-50, 4))
    s.advance_to(2.0)
    assert s.position_ticks == pytest.approx(-100 * TICKS_PER_S_PER_UNIT, abs=1)


def test_stall_then_overload_shuts_torque_off_until_reboot() -> None:
    s = _servo()
    s.overload_after_s = 0.5
    s.write(GOAL, _le(3000, 4))
    s.advance_to(0.1)
    moved = s.position_ticks
    s.set_stalled(True)
    s.advance_to(0.4)
    assert s.position_ticks == moved
    assert s.hardware_error == 0
    assert s.item("Present_Current") > 0
    s.advance_to(0.7)
    assert s.hardware_error == tables.HW_OVERLOAD
    assert not s.torque_enabled
    assert s.write(64, b"\x01") == tables.ERR_RESULT_FAIL
    s.clear_faults()
    s.reboot()
    assert s.hardware_error == 0
    assert s.write(64, b"\x01") == 0


def test_hardware_error_outside_shutdown_keeps_torque() -> None:
    s = _servo()
    s.raise_hardware_error(tables.HW_INPUT_VOLTAGE)  # not in Shutdown (52) by default
    assert s.item("Torque_Enable") == 1
    s.raise_hardware_error(tables.HW_OVERHEATING)
    assert s.item("Torque_Enable") == 0
    assert s.hardware_error == tables.HW_INPUT_VOLTAGE | tables.HW_OVERHEATING


def test_reboot_loses_the_turn_count_and_resets_ram() -> None:
    s = _servo()
    s.write(GOAL, _le(3 * 4096 + 100, 4))
    s.advance_to(10.0)
    assert s.position_ticks == 3 * 4096 + 100
    s.write(65, b"\x01")
    s.reboot()
    assert s.position_ticks == 100
    assert s.item("LED") == 0
    assert s.item("Operating_Mode") == 4  # EEPROM survives a reboot
    assert not s.torque_enabled


@pytest.mark.parametrize(("option", "kept_id"), [(0xFF, 1), (0x01, 9), (0x02, 9)])
def test_factory_reset_options(option: int, kept_id: int) -> None:
    s = EmulatedServo(9)
    s.write(8, b"\x03")
    s.write(11, b"\x04")
    assert s.factory_reset(option) == 0
    assert s.id == kept_id
    assert s.item("Operating_Mode") == 3
    assert s.item("Baud_Rate") == (3 if option == 0x02 else 1)
    assert s.factory_reset(0x05) == tables.ERR_DATA_RANGE


def test_reg_write_waits_for_action() -> None:
    s = EmulatedServo()
    assert s.action() == tables.ERR_RESULT_FAIL
    assert s.reg_write(65, b"\x01") == 0
    assert s.item("Registered_Instruction") == 1
    assert s.item("LED") == 0
    assert s.action() == 0
    assert s.item("LED") == 1
    assert s.item("Registered_Instruction") == 0


def test_homing_offset_shifts_present_position() -> None:
    s = EmulatedServo(position_ticks=1000)
    s.write(20, _le(-400, 4))
    assert s.position_ticks == 600
    assert s.item("Homing_Offset") == -400


def test_unknown_models_are_rejected() -> None:
    with pytest.raises(ValueError, match="unknown model"):
        EmulatedServo(1, "MX-28")
    with pytest.raises(ValueError, match="unknown model number"):
        EmulatedServo(1, 29)
    assert EmulatedServo(1, 1060).model == "XL430-W250"
    assert math.isfinite(EmulatedServo().velocity_ticks_per_s)


def test_control_table_items_do_not_overlap() -> None:
    # the servo finds the item of a whole-item write by its address alone
    items = sorted(tables.X_SERIES_CONTROL_TABLE.values())
    for (a, size), (b, _) in itertools.pairwise(items):
        assert a + size <= b


def test_an_unanswered_write_of_the_bytes_already_there_changes_nothing() -> None:
    s = _servo()  # torque on: EEPROM refuses writes
    s.write_unanswered(GOAL, _le(100, 4))
    assert s.item("Goal_Position") == 100
    before = bytes(s.memory)
    s.write_unanswered(11, bytes([4]))  # refused, but the same byte: skipped
    s.write_unanswered(11, bytes([3]))  # refused: nothing written
    s.write_unanswered(GOAL, _le(100, 4))
    assert bytes(s.memory) == before


def test_profile_motion_cruises_then_arrives_exactly_at_rest() -> None:
    vmax = 1000.0  # ticks/s, no acceleration limit: constant speed
    assert profile_motion(0.0, 0.0, 100.0, vmax, math.inf, 0.05) == pytest.approx((50.0, vmax))
    assert profile_motion(0.0, 0.0, -100.0, vmax, math.inf, 0.5) == (-100.0, 0.0)
    assert profile_motion(7.0, 0.0, 7.0, vmax, 10.0, 1.0) == (7.0, 0.0)
    # with an acceleration limit a: from rest, v = a t for the first steps
    pos, vel = profile_motion(0.0, 0.0, 1e6, vmax, 2000.0, 0.004)
    assert vel == pytest.approx(8.0)
    assert pos == pytest.approx((2.0 + 4.0 + 6.0 + 8.0) * 1e-3)  # explicit Euler, 1 ms steps
