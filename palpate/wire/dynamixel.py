"""The ROBOTIS X-series control table (Protocol 2.0) as plain data: a hardware fact.

Addresses, sizes, access rules, signedness, value ranges and factory defaults of the XM430-W350
(model number 1020) and XL430-W250 (1060), after the ROBOTIS e-manual ("Control Table of EEPROM
Area" / "RAM Area" of each model), plus the status-packet error numbers and the bits of
Hardware Error Status (address 70).

This module is pure data and has no imports from the rest of the stack. It is the one module of
``robot/`` that ``sim/`` may import: the driver (``robot.dynamixel.driver``) and the emulator
(``sim.dynamixel``) must agree on the same table, so it lives in exactly one place.

Emulator simplifications are documented in ``sim.dynamixel.servo``; here only the hardware.
"""

from __future__ import annotations

from typing import Final

# --- the control table: {item name: (address, size in bytes)} -------------------------------
X_SERIES_CONTROL_TABLE: Final[dict[str, tuple[int, int]]] = {
    # EEPROM area (addresses < 64): writable only while Torque_Enable == 0
    "Model_Number": (0, 2),
    "Model_Information": (2, 4),
    "Firmware_Version": (6, 1),
    "ID": (7, 1),
    "Baud_Rate": (8, 1),
    "Return_Delay_Time": (9, 1),
    "Drive_Mode": (10, 1),
    "Operating_Mode": (11, 1),
    "Secondary_ID": (12, 1),
    "Protocol_Type": (13, 1),
    "Homing_Offset": (20, 4),
    "Moving_Threshold": (24, 4),
    "Temperature_Limit": (31, 1),
    "Max_Voltage_Limit": (32, 2),
    "Min_Voltage_Limit": (34, 2),
    "PWM_Limit": (36, 2),
    "Current_Limit": (38, 2),
    "Velocity_Limit": (44, 4),
    "Max_Position_Limit": (48, 4),
    "Min_Position_Limit": (52, 4),
    "Startup_Configuration": (60, 1),
    "Shutdown": (63, 1),
    # RAM area
    "Torque_Enable": (64, 1),
    "LED": (65, 1),
    "Status_Return_Level": (68, 1),
    "Registered_Instruction": (69, 1),
    "Hardware_Error_Status": (70, 1),
    "Velocity_I_Gain": (76, 2),
    "Velocity_P_Gain": (78, 2),
    "Position_D_Gain": (80, 2),
    "Position_I_Gain": (82, 2),
    "Position_P_Gain": (84, 2),
    "Feedforward_2nd_Gain": (88, 2),
    "Feedforward_1st_Gain": (90, 2),
    "Bus_Watchdog": (98, 1),
    "Goal_PWM": (100, 2),
    "Goal_Current": (102, 2),
    "Goal_Velocity": (104, 4),
    "Profile_Acceleration": (108, 4),
    "Profile_Velocity": (112, 4),
    "Goal_Position": (116, 4),
    "Realtime_Tick": (120, 2),
    "Moving": (122, 1),
    "Moving_Status": (123, 1),
    "Present_PWM": (124, 2),
    "Present_Current": (126, 2),  # "Present_Load" on the XL430-W250 (same address and size)
    "Present_Velocity": (128, 4),
    "Present_Position": (132, 4),
    "Velocity_Trajectory": (136, 4),
    "Position_Trajectory": (140, 4),
    "Present_Input_Voltage": (144, 2),
    "Present_Temperature": (146, 1),
    "Backup_Ready": (147, 1),
}

EEPROM_END: Final = 64
"""Addresses below this are EEPROM: a write while torque is on answers Access Error."""
TABLE_SIZE: Final = 148
"""Bytes of the modelled table (the indirect address/data area from 168 on is not modelled)."""

READ_ONLY: Final[frozenset[str]] = frozenset(
    {
        "Model_Number",
        "Model_Information",
        "Firmware_Version",
        "Registered_Instruction",
        "Hardware_Error_Status",
        "Realtime_Tick",
        "Moving",
        "Moving_Status",
        "Present_PWM",
        "Present_Current",
        "Present_Velocity",
        "Present_Position",
        "Velocity_Trajectory",
        "Position_Trajectory",
        "Present_Input_Voltage",
        "Present_Temperature",
        "Backup_Ready",
    }
)

SIGNED: Final[frozenset[str]] = frozenset(
    {
        "Homing_Offset",
        "Goal_PWM",
        "Goal_Current",
        "Goal_Velocity",
        "Goal_Position",
        "Present_PWM",
        "Present_Current",
        "Present_Velocity",
        "Present_Position",
        "Velocity_Trajectory",
        "Position_Trajectory",
        "Min_Position_Limit",
        "Max_Position_Limit",
    }
)
"""Items whose raw bytes are two's-complement (the SDK returns every value as unsigned)."""

# --- models ---------------------------------------------------------------------------------
MODEL_NUMBERS: Final[dict[str, int]] = {"XM430-W350": 1020, "XL430-W250": 1060}
MODEL_NAMES: Final[dict[int, str]] = {v: k for k, v in MODEL_NUMBERS.items()}

MODEL_MISSING_ITEMS: Final[dict[str, frozenset[str]]] = {
    "XM430-W350": frozenset(),
    "XL430-W250": frozenset({"Current_Limit", "Goal_Current"}),
}
"""Items a model does not have: reading them gives 0, writing them answers Access Error."""

OPERATING_MODES: Final[dict[str, frozenset[int]]] = {
    # 0 current, 1 velocity, 3 position, 4 extended position (multi-turn),
    # 5 current-based position, 16 PWM
    "XM430-W350": frozenset({0, 1, 3, 4, 5, 16}),
    "XL430-W250": frozenset({1, 3, 4, 16}),
}
MODE_VELOCITY: Final = 1
MODE_POSITION: Final = 3
MODE_EXTENDED_POSITION: Final = 4
MODE_CURRENT_POSITION: Final = 5

_COMMON_DEFAULTS: Final[dict[str, int]] = {
    "Model_Information": 0,
    "Firmware_Version": 46,
    "ID": 1,
    "Baud_Rate": 1,
    "Return_Delay_Time": 250,
    "Drive_Mode": 0,
    "Operating_Mode": MODE_POSITION,
    "Secondary_ID": 255,
    "Protocol_Type": 2,
    "Homing_Offset": 0,
    "Moving_Threshold": 10,
    "PWM_Limit": 885,
    "Max_Position_Limit": 4095,
    "Min_Position_Limit": 0,
    "Startup_Configuration": 0,
    "Shutdown": 52,
    "Torque_Enable": 0,
    "LED": 0,
    "Status_Return_Level": 2,
    "Registered_Instruction": 0,
    "Hardware_Error_Status": 0,
    "Position_I_Gain": 0,
    "Feedforward_2nd_Gain": 0,
    "Feedforward_1st_Gain": 0,
    "Bus_Watchdog": 0,
    "Goal_PWM": 885,
    "Goal_Velocity": 0,
    "Profile_Acceleration": 0,
    "Profile_Velocity": 0,
    "Present_Input_Voltage": 120,
    "Present_Temperature": 30,
}

MODEL_DEFAULTS: Final[dict[str, dict[str, int]]] = {
    "XM430-W350": {
        **_COMMON_DEFAULTS,
        "Model_Number": 1020,
        "Temperature_Limit": 80,
        "Max_Voltage_Limit": 160,
        "Min_Voltage_Limit": 95,
        "Current_Limit": 1193,
        "Velocity_Limit": 200,
        "Velocity_I_Gain": 1920,
        "Velocity_P_Gain": 100,
        "Position_D_Gain": 0,
        "Position_P_Gain": 800,
        "Goal_Current": 1193,
    },
    "XL430-W250": {
        **_COMMON_DEFAULTS,
        "Model_Number": 1060,
        "Temperature_Limit": 72,
        "Max_Voltage_Limit": 140,
        "Min_Voltage_Limit": 60,
        "Velocity_Limit": 265,
        "Velocity_I_Gain": 1000,
        "Velocity_P_Gain": 100,
        "Position_D_Gain": 4000,
        "Position_P_Gain": 640,
    },
}
"""Factory defaults (EEPROM) and power-on values (RAM); items not listed power up as 0."""

VALUE_RANGES: Final[dict[str, tuple[int, int]]] = {
    "ID": (0, 252),
    "Baud_Rate": (0, 7),
    "Return_Delay_Time": (0, 254),
    "Drive_Mode": (0, 13),
    "Secondary_ID": (0, 255),
    "Protocol_Type": (1, 2),
    "Homing_Offset": (-1_044_479, 1_044_479),
    "Moving_Threshold": (0, 1023),
    "Temperature_Limit": (0, 100),
    "PWM_Limit": (0, 885),
    "Velocity_Limit": (0, 1023),
    "Max_Position_Limit": (0, 4095),
    "Min_Position_Limit": (0, 4095),
    "Startup_Configuration": (0, 3),
    "Shutdown": (0, 0x3D),
    "Torque_Enable": (0, 1),
    "LED": (0, 1),
    "Status_Return_Level": (0, 2),
    "Bus_Watchdog": (0, 127),
    "Profile_Acceleration": (0, 32767),
    "Profile_Velocity": (0, 32767),
}
"""Items with a documented range: a write outside it answers Data Range Error."""

# --- units and limits -----------------------------------------------------------------------
TICKS_PER_REV: Final = 4096
EXTENDED_POSITION_LIMIT: Final = 1_048_575
"""Goal_Position range in extended position mode: [-1 048 575, 1 048 575] ticks (+-256 rev)."""
VELOCITY_UNIT_RPM: Final = 0.229
"""Profile_Velocity, Velocity_Limit, Goal/Present_Velocity: rev/min per unit."""
ACCELERATION_UNIT_RPM2: Final = 214.577
"""Profile_Acceleration: rev/min^2 per unit."""
BAUD_RATES: Final[dict[int, int]] = {
    0: 9_600,
    1: 57_600,
    2: 115_200,
    3: 1_000_000,
    4: 2_000_000,
    5: 3_000_000,
    6: 4_000_000,
    7: 4_500_000,
}

# --- status packet error byte and Hardware Error Status -------------------------------------
ALERT_BIT: Final = 0x80
"""Set in every status packet's error byte while Hardware_Error_Status is non-zero."""

STATUS_ERRORS: Final[dict[int, str]] = {
    1: "Result Fail",
    2: "Instruction Error",
    3: "CRC Error",
    4: "Data Range Error",
    5: "Data Length Error",
    6: "Data Limit Error",
    7: "Access Error",
}
ERR_RESULT_FAIL: Final = 1
ERR_INSTRUCTION: Final = 2
ERR_CRC: Final = 3
ERR_DATA_RANGE: Final = 4
ERR_DATA_LENGTH: Final = 5
ERR_DATA_LIMIT: Final = 6
ERR_ACCESS: Final = 7

HARDWARE_ERRORS: Final[dict[int, str]] = {
    0x01: "Input Voltage Error",
    0x04: "Overheating Error",
    0x08: "Motor Encoder Error",
    0x10: "Electrical Shock Error",
    0x20: "Overload Error",
}
HW_INPUT_VOLTAGE: Final = 0x01
HW_OVERHEATING: Final = 0x04
HW_ENCODER: Final = 0x08
HW_ELECTRICAL_SHOCK: Final = 0x10
HW_OVERLOAD: Final = 0x20


def control_table(model: str) -> dict[str, tuple[int, int]]:
    """The items a model has, ``{name: (address, size)}``; raises KeyError for unknown models."""
    missing = MODEL_MISSING_ITEMS[model]
    return {k: v for k, v in X_SERIES_CONTROL_TABLE.items() if k not in missing}


def decode_hardware_error(bits: int) -> tuple[str, ...]:
    """Names of the bits set in a Hardware_Error_Status value, lowest bit first."""
    names = [name for bit, name in HARDWARE_ERRORS.items() if bits & bit]
    unknown = bits & ~sum(HARDWARE_ERRORS) & 0xFF
    if unknown:
        names.append(f"unknown bits 0x{unknown:02x}")
    return tuple(names)


def decode_status_error(error: int) -> tuple[str, ...]:
    """Names for a status packet's error byte: the error number and the Alert bit."""
    names = []
    number = error & 0x7F
    if number:
        names.append(STATUS_ERRORS.get(number, f"unknown error {number}"))
    if error & ALERT_BIT:
        names.append("Alert (hardware error, see Hardware_Error_Status)")
    return tuple(names)
