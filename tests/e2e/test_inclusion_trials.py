"""Single trials over a stiff inclusion (config/scenes/inclusions/bench.yaml): the world feels
it, the estimator is not told, and the estimate is the apparent modulus at that point."""

from __future__ import annotations

import pytest

from palpate import api

pytestmark = pytest.mark.slow  # a heavy module fixture: the quick subset leaves it out

SCENE = "scenes/inclusions/bench.yaml"


@pytest.fixture(scope="module")
def report() -> dict:
    return api.simulate(api.load_scene(SCENE)).as_dict()


@pytest.fixture(scope="module")
def rows(report) -> dict[str, dict]:
    return {row["sample"]: row for row in report["trials"]}


def test_every_trial_ends_and_estimates(rows) -> None:
    assert set(rows) == {"none", "below", "aside-3.5mm", "aside-14mm"}
    assert all(r["state"] == "done" and r["joint_kpa"] for r in rows.values())


def test_a_trial_over_the_inclusion_reads_stiffer_than_one_far_from_it(rows) -> None:
    kpa = {name: r["joint_kpa"] for name, r in rows.items()}
    assert kpa["below"] > 1.1 * kpa["aside-14mm"]
    assert kpa["below"] > kpa["aside-3.5mm"] > kpa["aside-14mm"]
    # far away (4 tip radii) the matrix is what the estimate reads
    assert kpa["aside-14mm"] == pytest.approx(kpa["none"], rel=0.03)


def test_the_world_says_what_it_holds(report) -> None:
    tissue = {s["sample"]: s["tissue_model"] for s in report["samples"]}
    assert tissue["below"]["inclusions"] == [
        {"center_mm": [0.0, 0.0, 5.0], "radius_mm": 2.5, "modulus_kpa": 1572.65}
    ]
    assert "inclusions" not in tissue["none"]
