"""Realistic servo-bus timing on the virtual clock: wire time, Return Delay Time, the FTDI
latency timer; the same simulated times on every transport; a trial that pays for them."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import pytest

from benchmarks.busrate import measured_rate, model_rate
from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.config.schema import ServoBusConfig
from palpate.robot.dynamixel.driver import DynamixelBus
from palpate.sim.clock import VirtualClock
from palpate.sim.dynamixel.bus import EmulatedBus
from palpate.sim.dynamixel.direct import direct_transport
from palpate.sim.dynamixel.timing import BusTiming
from palpate.sim.inprocess import InProcessPort
from palpate.simulation.trial import TrialSpec, bus_timing, run_sim_trial
from palpate.simulation.world import BENCH_COLUMN

CFG = ServoBusConfig(max_goal_step_deg=360.0, timeout_ms=500.0)


def test_exchange_adds_wire_time_return_delays_and_the_latency_timer() -> None:
    t = BusTiming(baudrate=1_000_000, latency_timer_s=16e-3)
    assert t.wire_time(100) == pytest.approx(1e-3)  # 10 bits a byte at 1 Mbps
    replies = [(21, 500e-6)] * 3
    line, got = t.exchange(0.0, 0.0, 17, replies)
    assert line == pytest.approx(17e-5 + 3 * (500e-6 + 21e-5))
    assert got == pytest.approx(16e-3)  # 63 bytes: the last one waits for the timer
    line, got = t.exchange(0.0, 0.0, 17, [(31, 0.0), (31, 0.0)])
    assert got == line  # 62 bytes fill a USB packet: it goes at once
    line2, got2 = t.exchange(0.0, 5e-3, 29, [])  # a sync write: no reply, after the line frees
    assert (line2, got2) == (pytest.approx(5e-3 + 29e-5), None)
    assert t.exchange(16e-3, 0.0, 1, [(10, 0.0)])[1] == pytest.approx(32e-3)
    with pytest.raises(ValueError, match="latency_timer_s"):
        BusTiming(latency_timer_s=0.0)


@pytest.mark.parametrize(
    ("baud", "latency_ms", "cycle_ms"), [(1_000_000, 16.0, 16.0), (1_000_000, 1.0, 3.0)]
)
def test_read_modify_cycles_through_the_driver(
    baud: int, latency_ms: float, cycle_ms: float
) -> None:
    timing = BusTiming(baudrate=baud, latency_timer_s=latency_ms * 1e-3)
    rate = measured_rate(timing, cycles=40)
    assert 1e3 / rate == pytest.approx(cycle_ms, rel=1e-9)
    assert rate == pytest.approx(model_rate(timing), rel=1e-9)


def test_slow_baud_rate_is_wire_bound() -> None:
    timing = BusTiming(baudrate=57_600, latency_timer_s=1e-3)
    rate = measured_rate(timing, cycles=40)
    assert rate == pytest.approx(model_rate(timing), rel=0.01)
    assert rate < 50  # about 23 ms of wire time and return delays per cycle


def _cycle_times(transport: str, cycles: int = 15) -> list[float]:
    timing = BusTiming(baudrate=1_000_000, latency_timer_s=1e-3)
    clock = VirtualClock()
    bus = EmulatedBus.from_config(CFG, clock=clock, timing=timing)
    kwargs: dict[str, Any] = {}
    if transport == "direct":
        port, kwargs["packet_handler"] = direct_transport(bus)
    elif transport == "sdk":
        port = InProcessPort(bus)
    else:
        port = bus.open()
    times = []
    try:
        with DynamixelBus.from_config(CFG, port=port, **kwargs) as driver:
            driver.set_torque(True)
            for k in range(cycles):
                driver.read_state()
                driver.write_goals({"translation": 0.01 * math.sin(k)})
                times.append(clock.now())
    finally:
        bus.close()
    return times


def test_every_transport_sees_the_same_simulated_times() -> None:
    direct = _cycle_times("direct")
    assert _cycle_times("sdk") == direct
    assert _cycle_times("pty") == direct  # the emulator thread advances the clock
    assert direct[1] - direct[0] == pytest.approx(3e-3)


def test_a_trial_on_a_realistic_bus_runs_slower_in_simulated_time() -> None:
    stack = load_stack()
    scene = load(SceneConfig, resolve("scenes/bench.yaml"))
    fidelity = dataclasses.replace(scene.fidelity, bus_timing="realistic", latency_timer_ms=1.0)
    timed = dataclasses.replace(scene, fidelity=fidelity)
    timing = bus_timing(fidelity, stack.servos)
    assert timing == BusTiming(baudrate=stack.servos.baudrate, latency_timer_s=1e-3)
    assert bus_timing(scene.fidelity, stack.servos) is None
    spec = TrialSpec("S8", "bench", "S8", 314.53e3, 0.45, BENCH_COLUMN, "downward", 0.0, 44e-3, 3)
    ideal = run_sim_trial(spec, scene, stack)
    slow = run_sim_trial(spec, timed, stack)
    assert ideal.state == slow.state == "done"
    tick = 1.0 / scene.control_rate_hz
    assert ideal.sim_time / ideal.ticks == pytest.approx(tick, rel=0.01)
    # each tick waits for its sync read: the next millisecond of the latency timer, about 3 ms
    assert slow.sim_time / slow.ticks > tick + 1.5e-3
    assert slow.joint is not None
    assert slow.joint.modulus is not None
