"""The campaign section of ``palpate bench``: its fidelity levels and its Pareto front."""

from __future__ import annotations

import dataclasses

from config import load, resolve
from config.scene import SceneConfig
from palpate.benchmarks.campaign import CHEAPEST, LEVELS, REFERENCE, pareto_front

BENCH = load(SceneConfig, resolve("scenes/bench.yaml"))


def _level(name: str, transport: str = "fast") -> SceneConfig:
    level = next(x for x in LEVELS if x.name == name and x.transport == transport)
    return level.change(BENCH)


def test_each_level_changes_only_what_it_names() -> None:
    assert _level(REFERENCE) == _level(REFERENCE, "wire") == BENCH
    assert {x.transport for x in LEVELS if x.name == REFERENCE} == {"wire", "fast"}
    lean = _level(CHEAPEST)
    assert (lean.control_rate_hz, lean.board_rate_hz) == (20.0, 20.0)
    assert dataclasses.replace(lean, control_rate_hz=250.0, board_rate_hz=250.0) == BENCH
    gravity = _level("+ gravity")
    assert gravity.fidelity.gravity
    assert not BENCH.fidelity.gravity
    assert dataclasses.replace(gravity.fidelity, gravity=False) == BENCH.fidelity
    closed = _level("closed-form tissue")
    assert closed.fidelity.tissue_model == "closed-form"
    assert closed.samples == BENCH.samples
    bus = _level("+ realistic bus, 1 ms timer")
    assert (bus.fidelity.bus_timing, bus.fidelity.latency_timer_ms) == ("realistic", 1.0)
    assert len({(x.name, x.transport) for x in LEVELS}) == len(LEVELS)


def test_pareto_front_keeps_only_points_nothing_beats() -> None:
    points = [(10.0, 1.0), (1.0, 5.0), (5.0, 5.0), (3.0, 2.0), (10.0, 1.0), (20.0, 0.5)]
    # (5, 5) is beaten by (3, 2); both (10, 1) stay (ties), ordered by cost
    assert pareto_front(points) == [1, 3, 0, 4, 5]
    assert pareto_front([]) == []
    assert pareto_front([(2.0, 2.0)]) == [0]
