"""The x-y stage's pure mapping: position <-> shafts through the lead screw, its travel as a
guard, software homing, and the planned travel time of a move."""

from __future__ import annotations

import math

import pytest

from palpate.config.xystage import XYStageConfig
from palpate.robot.drive import JointLimitError
from palpate.robot.xystage import STAGE_X, STAGE_Y, StageController, StageLimitError, XYAxes

CFG = XYStageConfig(lead_mm_per_rev=2.0, x_travel_mm=(-10.0, 12.0), home_mm=(1.0, -1.0))


def test_a_lead_screw_turns_once_per_lead_from_home() -> None:
    axes = XYAxes(CFG)
    shafts = axes.shafts((3e-3, -1e-3))
    assert shafts[STAGE_X] == pytest.approx(2 * math.pi)  # 2 mm from home: one turn
    assert shafts[STAGE_Y] == pytest.approx(0.0)
    assert axes.position(shafts) == pytest.approx((3e-3, -1e-3))


def test_homing_takes_the_present_shafts_as_home() -> None:
    axes = XYAxes(CFG).homed({STAGE_X: 5.0, STAGE_Y: -7.0})
    assert axes.position({STAGE_X: 5.0, STAGE_Y: -7.0}) == pytest.approx(CFG.home)
    assert axes.shafts((1e-3, 0.0))[STAGE_Y] == pytest.approx(-7.0 + math.pi)


@pytest.mark.parametrize("goal", [(12.5e-3, 0.0), (0.0, -15.5e-3)])
def test_a_goal_beyond_the_travel_is_refused_naming_the_key(goal: tuple[float, float]) -> None:
    with pytest.raises(StageLimitError, match="_travel_mm") as err:
        XYAxes(CFG).shafts(goal)
    assert isinstance(err.value, JointLimitError)  # caught where a drive limit is


def test_travel_time_is_a_trapezoid_or_a_triangle() -> None:
    stage = StageController(bus=None, cfg=CFG)  # type: ignore[arg-type]  # no bus needed
    v, a = CFG.max_speed, CFG.max_accel
    far = (CFG.home[0] + 10e-3, CFG.home[1])
    assert stage.travel_time(far) == pytest.approx(10e-3 / v + v / a)
    near = (CFG.home[0], CFG.home[1] + 0.1e-3)
    assert stage.travel_time(near) == pytest.approx(2 * math.sqrt(0.1e-3 / a))


@pytest.mark.parametrize(
    ("keys", "problem"),
    [
        ({"x_travel_mm": (5.0, -5.0)}, "x_travel_mm"),
        ({"home_mm": (0.0, 20.0)}, "home_mm"),
        ({"y": {"id": 4}}, "must differ"),
    ],
)
def test_a_bad_stage_is_refused(keys: dict[str, object], problem: str) -> None:
    from palpate.config.loader import ConfigError, from_mapping

    with pytest.raises(ConfigError, match=problem):
        from_mapping(XYStageConfig, keys, "robot.yaml", "stage")
