"""Where probing expects the next touch and how far either side (robot.probe_plan): with three
touches or more the doubt is the fitted plane's, propagated to the ray by direction; the way
out's retract is planned over the roll the routine will take (issue 18)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.estimation.pose.surface import SurfaceGeometry
from palpate.robot.probe_plan import _distance_to_line, _model
from palpate.robot.probing import ProbeRoutine, Touch
from palpate.robot.trial.setup import prober_for, trial_plan

STACK = load_stack()
TILTED = load(SceneConfig, resolve("scenes/tilted.yaml"))
CONTACT = 42e-3


def routine(tube_name: str, roll: float) -> ProbeRoutine:
    tube = next(t for t in STACK.tubes if t.name == tube_name)
    plan = trial_plan(TILTED.campaign, STACK, roll=roll, contact=CONTACT, home=40e-3)
    build = prober_for(TILTED.campaign, STACK, tube)
    assert build is not None
    r = build(plan)
    assert isinstance(r, ProbeRoutine)
    return r


def touches_on(r: ProbeRoutine, plane: SurfaceGeometry, rolls: list[float]) -> list[Touch]:
    return [r.geometry.touch(a, r.geometry.advance_to(plane, a)) for a in rolls]


def test_three_touches_on_one_side_predict_the_other_side_within_a_directional_bound() -> None:
    r = routine("bent30", 0.0)
    geo, s = r.geometry, r.settings
    first = geo.touch(0.0, CONTACT)
    normal = -np.asarray(first.tangent) + np.array([0.0, 0.1, 0.05])  # a few degrees off square
    plane = SurfaceGeometry.make(np.asarray(first.centre), normal)
    step = math.radians(20.0)
    touches = touches_on(r, plane, [0.0, step / 4, step])
    x, slack = geo.predict(touches, -step, s)
    assert x == pytest.approx(geo.advance_to(plane, -step), abs=1e-7)  # the plane itself
    # the touches' doubt, propagated: a seeded Monte Carlo of sigma along each ray agrees
    rng = np.random.default_rng(0)
    xs = []
    for _ in range(200):
        moved = [
            dataclasses.replace(t, centre=tuple(np.add(t.centre, rng.normal(0.0, s.sigma) * ray)))
            for t, ray in ((t, np.asarray(t.tangent)) for t in touches)
        ]
        xs.append(geo.predict(moved, -step, s)[0])
    spread = slack - 3.0 * s.sigma  # predict adds the next touch's own 3 sigma
    assert spread == pytest.approx(3.0 * float(np.std(xs)), rel=0.2)
    # tighter than the normal's whole doubt times the distance (the slope along the roll is
    # pinned by the touches' span; only the tilt across it is loose)
    _, line, tilt = _model(touches, s.sigma)
    c = np.asarray(geo.touch(-step, x).centre)
    assert spread < 0.5 * _distance_to_line(c, line) * math.tan(tilt)


def test_the_way_out_is_planned_over_the_short_way_round() -> None:
    """An upward trial's IK may answer a roll a whole turn from the touches (-167 deg for 193):
    the retract is planned over the roll the routine takes, not over a whole turn of rays
    (some nearly along the surface, which sent the stage back to its limit)."""
    r = routine("bent50", math.pi)
    made = [(180.0, 42.3239, 0.361), (184.1309, 41.7919, 0.3658), (163.4766, 46.5534, 0.3704),
            (196.5234, 41.4265, 0.3292)]  # fmt: skip
    touches = [
        dataclasses.replace(r.geometry.touch(math.radians(a), x * 1e-3), depth=d * 1e-3)
        for a, x, d in made
    ]
    result = r.geometry.replan(touches, r.plan, r.settings)
    assert result.reachable
    lo, hi = r.geometry.roll_limits
    assert lo <= result.roll <= hi
    assert abs(result.roll - touches[-1].roll) < math.radians(10.0)
    assert result.retract_to > 35e-3  # behind the pose's stand-off, not at the stage's limit
    assert result.retract_to < result.contact_advance - r.settings.standoff
