"""The order of the probing touches and the way out (robot.probing, issue 18)."""

from __future__ import annotations

import math

import pytest

from palpate.robot.probe_plan import nearest_turn
from palpate.robot.probing import Touch, _near_side_last


def touch(roll: float, advance: float) -> Touch:
    return Touch(roll, advance, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0))


@pytest.mark.parametrize(("step", "nearer"), [(0.1, True), (0.1, False), (-0.1, True)])
def test_the_last_touch_is_on_the_side_the_surface_comes_nearer(step: float, nearer: bool) -> None:
    rolls = [0.0, step, 4 * step, -4 * step]
    touches = [touch(0.0, 0.042), touch(step, 0.041 if nearer else 0.043)]
    order = _near_side_last(rolls, touches)
    assert sorted(order) == sorted(rolls)
    assert order[:2] == rolls[:2]
    toward = math.copysign(1.0, step) * (1.0 if nearer else -1.0)
    assert order[3] * toward > 0 > order[2] * toward


def test_three_touches_keep_their_order() -> None:
    assert _near_side_last([0.0, 0.1, 0.4], [touch(0.0, 0.042), touch(0.1, 0.041)]) == [
        0.0, 0.1, 0.4,
    ]  # fmt: skip


def test_the_way_out_never_rolls_the_long_way_round() -> None:
    limits = (math.radians(-200.0), math.radians(200.0))
    near = math.radians(190.0)
    assert nearest_turn(math.radians(-179.0), near, limits) == pytest.approx(math.radians(181.0))
    assert nearest_turn(math.radians(10.0), near, limits) == pytest.approx(math.radians(10.0))
    # beyond the limits one turn on: the long way is the only way
    assert nearest_turn(math.radians(-150.0), near, limits) == pytest.approx(math.radians(-150.0))
