"""Servo bus and kinematics speed: the control tick through dynamixel_sdk + pty + emulator.

A control tick is what the indentation loop does every period: one sync write of the three
goals and one sync read of the three servos' state, through :class:`DynamixelBus` (the real
SDK) to the emulated X-series servos on a pseudo-terminal, in real-time mode (the emulator
integrates motion on wall time, as ``palpate emulate`` does). The target is >= 500 Hz. The
same tick through bare SDK group objects shows the driver's overhead; IK/FK timings show what a
trial pays for planning. What a real U2D2 bus allows (wire time, Return Delay Time, the FTDI
latency timer at 16 ms and 1 ms) is counted on the virtual clock
(:mod:`benchmarks.busrate`).
"""

from __future__ import annotations

import math
import statistics
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from benchmarks import busrate
from benchmarks.report import BenchContext, BenchSection, Table, median_time
from palpate.config.schema import DEFAULT_TUBES, ServoBusConfig
from palpate.robot.dynamixel.driver import DynamixelBus
from palpate.robot.kinematics import forward, inverse
from palpate.sim.dynamixel.bus import EmulatedBus

TARGET_HZ = 500.0


def _rates(fn: Callable[[], object], repeats: int, number: int) -> list[float]:
    """Calls per second of ``fn`` for each of ``repeats`` runs of ``number`` calls."""
    rates = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(number):
            fn()
        rates.append(number / (time.perf_counter() - t0))
    return rates


def _bus_rows(ctx: BenchContext) -> tuple[list[Sequence[Any]], dict[str, float]]:
    # a generous reply timeout: a busy machine may deschedule the emulator thread for a while;
    # the timeout only matters when a reply is late, so it does not change the rates measured
    cfg = ServoBusConfig(max_goal_step_deg=360.0, timeout_ms=200.0)
    number = 150 if ctx.quick else 500
    rows: list[Sequence[Any]] = []
    summary: dict[str, float] = {}
    with (
        EmulatedBus.from_config(cfg) as emulator,
        DynamixelBus.from_config(cfg, port=emulator.port) as bus,
    ):
        bus.set_torque(True)
        start = bus.read_state()
        k = [0]

        def goals() -> dict[str, float]:
            k[0] += 1
            wiggle = 0.01 * math.sin(0.01 * k[0])
            return {name: s.position + wiggle for name, s in start.items()}

        def tick() -> None:
            bus.write_goals(goals())
            bus.read_state()

        def read_only() -> None:
            bus.read_state()

        bus.read_state()  # warm up
        # (a sync write alone gets no reply, so timing it alone would only measure how fast
        # packets queue up on the pty; it is measured as part of the tick)
        cases = [
            ("control tick (sync write 3 + sync read 3)", tick),
            ("sync read of 3 servos (14 B each)", read_only),
        ]
        for label, fn in cases:
            rates = _rates(fn, ctx.repeats, number)
            rows.append([label, statistics.median(rates), min(rates), max(rates)])
            summary.setdefault("control_tick_hz", statistics.median(rates))
        packets = emulator.packets_handled
    summary["emulator_packets"] = float(packets)
    return rows, summary


def _kinematics_rows(ctx: BenchContext) -> list[Sequence[Any]]:
    rng = np.random.default_rng(ctx.seed)
    normals = rng.normal(size=(64, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    target = np.array([0.12, 0.0, -0.03])
    i = [0]

    def ik() -> None:
        i[0] = (i[0] + 1) % len(normals)
        inverse(
            DEFAULT_TUBES,
            target,
            normals[i[0]],
            tip_radius=3.5e-3,
            translation_limits=(0.0, 0.08),
        )

    def fk() -> None:
        forward(DEFAULT_TUBES[2], 0.3, 0.04)

    number = 100 if ctx.quick else 300
    return [
        ["inverse (4 tubes)", median_time(ik, ctx.repeats, number) * 1e6],
        ["forward (one pose)", median_time(fk, ctx.repeats, number) * 1e6],
    ]


def run(ctx: BenchContext) -> BenchSection:
    bus_rows, summary = _bus_rows(ctx)
    tick_hz = summary["control_tick_hz"]
    bus_table = Table(
        title="Servo bus: dynamixel_sdk -> pty -> emulated XM430/XL430 (real-time mode)",
        columns=["operation", "median Hz", "min Hz", "max Hz"],
        rows=bus_rows,
        note=(
            f"{ctx.repeats} repeats; control tick target >= {TARGET_HZ:.0f} Hz: "
            f"{'met' if tick_hz >= TARGET_HZ else 'NOT met'} ({tick_hz:.0f} Hz, "
            f"{1e3 / tick_hz:.2f} ms per tick)"
        ),
    )
    timed_rows, timed = busrate.rows(60 if ctx.quick else 200)
    summary.update(timed)
    timed_table = Table(
        title="Servo bus with real timing: read-modify cycles per simulated second "
        "(sync read of 3 + sync write of 3; sim/dynamixel/timing.py)",
        columns=["baud rate", "latency timer ms", "cycles/s", "model cycles/s", "ms per cycle"],
        rows=timed_rows,
        note=(
            "the driver on the emulated bus with wire time, Return Delay Time 500 us and the "
            "FTDI latency timer, on the virtual clock; Linux's default timer is 16 ms: "
            "echo 1 > /sys/bus/usb-serial/devices/ttyUSB0/latency_timer sets it to 1 ms"
        ),
    )
    kin_table = Table(
        title="Kinematics",
        columns=["operation", "median us per call"],
        rows=_kinematics_rows(ctx),
    )
    summary["control_tick_ms"] = 1e3 / tick_hz
    summary["control_tick_target_met"] = float(tick_hz >= TARGET_HZ)
    return BenchSection(name="robot", tables=[bus_table, timed_table, kin_table], summary=summary)
