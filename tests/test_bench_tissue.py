"""The tissue sections of ``palpate bench``: the levels they run and the FE tables they print."""

from __future__ import annotations

from benchmarks.tissue import LEVELS, VISCO, level_scene
from benchmarks.tissue_fe import _markdown_tables
from palpate.config import load, resolve
from palpate.config.scene import SceneConfig

BENCH = load(SceneConfig, resolve("scenes/bench.yaml"))


def test_each_level_changes_only_what_it_names() -> None:
    closed = level_scene(BENCH, "closed form")
    assert closed.fidelity.tissue_model == "closed-form"
    assert {s.material for s in closed.samples} == {"linear"}
    neo = level_scene(BENCH, "FE neo-Hookean")
    assert neo == BENCH  # the shipped scene is this level
    ve = level_scene(BENCH, "FE neo-Hookean + SLS", 2.0)
    assert ve.fidelity.viscoelastic
    assert ve.campaign.indent_speed_mm_per_s == 2.0
    assert all(s.relaxation_time_s == VISCO["relaxation_time_s"] for s in ve.samples)
    assert len(LEVELS) == 4


def test_markdown_sections_become_titled_tables() -> None:
    lines = ["### Validation", "", "Thick layer:", "", "| a | b |", "| --- | --- |", "| 1 | 2 |"]
    lines += ["", "Thin layer:", "| c |", "| --- |", "| 3 |", "| 4 |"]
    first, second = _markdown_tables(lines)
    assert (first.title, list(first.columns), first.rows) == (
        "Thick layer",
        ["a", "b"],
        [["1", "2"]],
    )
    assert (second.title, second.rows) == ("Thin layer", [["3"], ["4"]])
