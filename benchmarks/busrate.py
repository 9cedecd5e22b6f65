"""The real bus's cost: read-modify cycles per second of a U2D2 bus, on the virtual clock.

A read-modify cycle is what the control loop needs from the bus each tick: one sync read of the
three servos' state and one sync write of their goals, through the real driver
(:class:`robot.dynamixel.DynamixelBus`) to the emulated servos with realistic bus timing
(:mod:`sim.dynamixel.timing`: wire time at the baud rate, each servo's Return Delay Time, the
FTDI latency timer). The rate is counted in simulated seconds, so it is what the bus allows, not
what this machine's CPU allows; the model's closed form is printed beside it as a check.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from palpate.config.schema import ServoBusConfig
from palpate.robot.dynamixel.driver import DynamixelBus
from palpate.robot.dynamixel.replies import GOAL_LEN, STATE_LEN
from palpate.sim.clock import VirtualClock
from palpate.sim.dynamixel import protocol
from palpate.sim.dynamixel.bus import EmulatedBus
from palpate.sim.dynamixel.direct import direct_transport
from palpate.sim.dynamixel.timing import RETURN_DELAY_UNIT_S, BusTiming
from palpate.wire import dynamixel as tables

CASES = ((1_000_000, 16.0), (1_000_000, 1.0), (57_600, 16.0), (57_600, 1.0))


def measured_rate(timing: BusTiming, cycles: int = 100) -> float:
    """Read-modify cycles per simulated second through the driver on an emulated timed bus."""
    cfg = ServoBusConfig(max_goal_step_deg=360.0)
    clock = VirtualClock()
    bus = EmulatedBus.from_config(cfg, clock=clock, timing=timing)
    port, handler = direct_transport(bus)
    with DynamixelBus.from_config(cfg, port=port, packet_handler=handler) as driver:
        driver.set_torque(True)
        state = driver.read_state()
        goals = {name: s.position for name, s in state.items()}
        t0 = clock.now()
        for k in range(cycles):
            state = driver.read_state()
            # a new goal each cycle (a goal the servos hold already is not sent)
            driver.write_goals({n: g + 1e-2 * (k + 1) for n, g in goals.items()})
        return cycles / (clock.now() - t0)


def model_rate(timing: BusTiming, servos: int = 3) -> float:
    """The same cycle from :meth:`BusTiming.read_modify_rate` (packet sizes of the driver's
    requests, the servos' default Return Delay Time)."""
    read = len(protocol.encode(protocol.BROADCAST_ID, protocol.INST_SYNC_READ, bytes(4 + servos)))
    reply = len(protocol.encode_status(1, 0, bytes(STATE_LEN)))
    write_params = 4 + servos * (1 + GOAL_LEN)
    write = len(
        protocol.encode(protocol.BROADCAST_ID, protocol.INST_SYNC_WRITE, bytes(write_params))
    )
    delay = tables.MODEL_DEFAULTS["XM430-W350"].get("Return_Delay_Time", 250) * RETURN_DELAY_UNIT_S
    return timing.read_modify_rate(read, [reply] * servos, delay, write)


def rows(cycles: int = 100) -> tuple[list[Sequence[Any]], dict[str, float]]:
    """One row per (baud rate, latency timer): measured and model cycles/s, ms per cycle."""
    out: list[Sequence[Any]] = []
    summary: dict[str, float] = {}
    for baud, latency_ms in CASES:
        timing = BusTiming(baudrate=baud, latency_timer_s=latency_ms * 1e-3)
        rate = measured_rate(timing, cycles)
        out.append([f"{baud / 1e3:g} kbps", latency_ms, rate, model_rate(timing), 1e3 / rate])
        summary[f"read_modify_hz_{baud}_{latency_ms:g}ms"] = rate
    return out, summary
