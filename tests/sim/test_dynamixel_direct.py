"""The register-level servo path decides what the SDK path decides: one scripted session of the
driver (connect, goals, motion, reads, access errors, lost and corrupt replies, a hardware error,
reboot, close) runs over dynamixel-sdk's packets on the in-process port and over
``sim.dynamixel.direct``, and every return value, exception and register ends the same."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import pytest

from palpate.config.schema import ServoBusConfig
from palpate.robot.dynamixel.driver import DynamixelBus
from palpate.sim.clock import VirtualClock
from palpate.sim.dynamixel.bus import EmulatedBus
from palpate.sim.dynamixel.direct import DirectPacketHandler, DirectPort, direct_transport
from palpate.sim.inprocess import InProcessPort
from palpate.wire import dynamixel as tables

CFG = ServoBusConfig(retries=2, timeout_ms=50.0)


def _outcome(call: Callable[[], Any]) -> Any:
    try:
        return ("ok", call())
    except Exception as exc:  # the exception's type and message are the outcome
        return ("raised", type(exc).__name__, str(exc))


def _session(transport: str) -> tuple[list[Any], list[bytes]]:
    clock = VirtualClock()
    emulator = EmulatedBus.from_config(CFG, clock=clock)
    if transport == "direct":
        port, handler = direct_transport(emulator)
        driver = DynamixelBus.from_config(CFG, port=port, packet_handler=handler)
    else:
        in_process = InProcessPort(emulator)
        in_process.reply_timeout_ms = 1.0
        driver = DynamixelBus.from_config(CFG, port=in_process)
    translation = emulator.servo(CFG.translation.id)
    out: list[Any] = []
    steps: list[Callable[[], Any]] = [
        driver.connect,
        lambda: driver.ping("translation"),
        lambda: driver.set_profile("translation", 3.0, 40.0),
        lambda: driver.set_torque(True),
        lambda: driver.write_goals({"translation": 2.0, "outer_roll": -0.3, "inner_roll": 0.1}),
        lambda: clock.advance(0.05),
        driver.read_state,
        lambda: driver.read_item("translation", "Present_Position"),
        lambda: driver.read_item("outer_roll", "Present_Velocity"),
        lambda: driver.write_item("translation", "Present_Position", 5),  # read-only
        lambda: driver.write_item("translation", "Operating_Mode", 3),  # EEPROM, torque on
        lambda: translation.drop_replies(1),
        driver.read_state,  # one lost reply: retried
        lambda: translation.corrupt_replies(1),
        driver.read_state,  # one corrupt reply: retried
        lambda: translation.drop_replies(10),
        driver.read_state,  # silent: a transport error after the retries
        translation.clear_faults,
        lambda: translation.raise_hardware_error(tables.HW_OVERLOAD),
        driver.read_state,  # the Alert bit: a fault with the decoded bits
        lambda: driver.read_hardware_error("translation"),
        lambda: driver.reboot("translation"),
        lambda: driver.set_torque(True),
        lambda: driver.write_goals({"translation": 2.5, "outer_roll": 0.0, "inner_roll": 0.0}),
        lambda: clock.advance(0.2),
        driver.read_state,
        driver.close,
        driver.read_state,  # closed
    ]
    for step in steps:
        out.append(_outcome(step))
    memories = [bytes(s.memory) for s in emulator.servos]
    return out, memories


def test_the_direct_path_decides_what_the_sdk_path_decides() -> None:
    sdk_out, sdk_memory = _session("sdk")
    direct_out, direct_memory = _session("direct")
    assert direct_out == sdk_out
    assert direct_memory == sdk_memory
    kinds = [o[0] for o in sdk_out]
    assert kinds.count("raised") >= 5  # the script reaches the error paths it is meant to
    assert any("hardware error" in str(o) for o in sdk_out)
    assert any("ServoTransportError" in str(o) for o in sdk_out)


def test_replies_follow_the_status_return_level_and_ids() -> None:
    bus = EmulatedBus.from_config(CFG, clock=VirtualClock())
    port, handler = DirectPort(bus), DirectPacketHandler()
    sid = CFG.translation.id
    model, result, error = handler.ping(port, sid)
    assert (model, result, error) == (tables.MODEL_NUMBERS[CFG.translation.model], 0, 0)
    assert handler.ping(port, 0xFE)[1] == -9000  # COMM_NOT_AVAILABLE, as the SDK
    assert handler.ping(port, 99)[1] == -3001  # nobody there: COMM_RX_TIMEOUT
    level = tables.X_SERIES_CONTROL_TABLE["Status_Return_Level"][0]
    # the new level already governs this write's own reply, as on the wire
    assert handler.write1ByteTxRx(port, sid, level, 0) == (-3001, 0)
    data, result, _ = handler.readTxRx(port, sid, level, 1)
    assert (data, result) == ([], -3001)  # level 0 answers pings only
    assert handler.ping(port, sid)[1] == 0
    assert handler.getTxRxResult(-3001) == "[TxRxResult] There is no status packet!"


@pytest.mark.parametrize("goal", [0.0, -math.pi, 50.0])
def test_sync_write_then_sync_read_round_trip(goal: float) -> None:
    clock = VirtualClock()
    bus = EmulatedBus.from_config(CFG, clock=clock)
    port, handler = direct_transport(bus)
    with DynamixelBus.from_config(CFG, port=port, packet_handler=handler) as driver:
        driver.max_goal_step = 100.0
        driver.set_torque(True)
        sent = driver.write_goals({"translation": goal})
        clock.advance(60.0)
        state = driver.read_state()
        assert state["translation"].position == pytest.approx(sent["translation"], abs=1e-12)
        assert not state["translation"].moving
