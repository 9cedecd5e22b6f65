"""The campaign section of ``palpate bench``: its fidelity levels and its Pareto front."""

from __future__ import annotations

import dataclasses

from benchmarks.campaign import CHEAPEST, LEVELS, REFERENCE, LevelRow, pareto_front, usable
from palpate.config import load, resolve
from palpate.config.scene import SceneConfig

BENCH = load(SceneConfig, resolve("scenes/bench.yaml"))


def _level(name: str, transport: str = "fast") -> SceneConfig:
    level = next(x for x in LEVELS if x.name == name and x.transport == transport)
    return level.change(BENCH)


def test_each_level_changes_only_what_it_names() -> None:
    assert _level(REFERENCE) == _level(REFERENCE, "wire") == BENCH
    assert {x.transport for x in LEVELS if x.name == REFERENCE} == {"wire", "fast"}
    lean = _level(CHEAPEST)
    assert (lean.control_rate_hz, lean.board_rate_hz) == (25.0, 25.0)
    assert lean.fidelity.contact_grid_um == 40.0
    assert BENCH.fidelity.contact_grid_um is None
    back = dataclasses.replace(lean.fidelity, contact_grid_um=None)
    assert (
        dataclasses.replace(lean, control_rate_hz=250.0, board_rate_hz=250.0, fidelity=back)
        == BENCH
    )
    slow = _level("20 Hz")
    assert dataclasses.replace(slow, control_rate_hz=250.0, board_rate_hz=250.0) == BENCH
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


def _row(coverage: float | None, worst: float | None) -> LevelRow:
    return LevelRow("x", "fast", 55, 0.05, 50.0, 0.02, worst, coverage, 0.3)


def test_a_level_is_usable_only_with_coverage_and_a_bounded_worst_error() -> None:
    assert usable(_row(0.964, 0.146))  # the 50 Hz level of docs/speed.md
    assert not usable(_row(0.745, 0.596))  # 20 Hz: cheap, useless
    assert not usable(_row(0.964, 0.40))  # covered but one estimate far off
    assert not usable(_row(0.85, 0.10))
    assert not usable(_row(None, None))  # no estimate at all


def test_the_shipped_lean_scene_is_the_lean_level() -> None:
    """config/scenes/bench-lean.yaml is bench.yaml at the cheapest usable level, nothing else."""
    shipped = load(SceneConfig, resolve("scenes/bench-lean.yaml"))
    assert dataclasses.replace(shipped, name=BENCH.name) == _level(CHEAPEST)
