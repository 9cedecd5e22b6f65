"""The FBG interlock of probing's moves (robot.probing): a roll that meets the surface is held
and the stage backs off until the beam is free, then the roll goes on (issue 18)."""

from __future__ import annotations

import dataclasses
import math

from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.robot.indentation import Command, Observation
from palpate.robot.probing import TOUCH_BOW, ProbeRoutine
from palpate.robot.trial.setup import prober_for, trial_plan

STACK = load_stack()
TILTED = load(SceneConfig, resolve("scenes/tilted.yaml"))
CONTACT = 42e-3


def moving_routine() -> tuple[ProbeRoutine, float]:
    """A routine that has made its first touch and is rolling to the second; its target roll."""
    tube = next(t for t in STACK.tubes if t.name == "bent30")
    plan = trial_plan(TILTED.campaign, STACK, roll=0.0, contact=CONTACT, home=40e-3)
    build = prober_for(TILTED.campaign, STACK, tube)
    assert build is not None
    routine = build(plan)
    assert isinstance(routine, ProbeRoutine)
    touch = routine.geometry.touch(0.0, CONTACT)
    routine.touches.append(dataclasses.replace(touch, depth=0.1e-3))
    first = routine._lift(obs(0.0, CONTACT, 0.0))
    assert isinstance(first, Command)
    return routine, routine.roll


def obs(roll: float, advance: float, strain: float, t: float = 0.0) -> Observation:
    return Observation(t, advance, roll, (strain, -strain, strain), False)


def free_ticks(routine: ProbeRoutine, roll: float, advance: float, n: int) -> Command:
    cmd = None
    for _ in range(n):
        cmd = routine.step(obs(roll, advance, 0.0))
    assert isinstance(cmd, Command)
    return cmd


def test_a_bow_during_a_roll_holds_the_roll_and_backs_off() -> None:
    routine, target = moving_routine()
    assert abs(target) > math.radians(2.0)  # the second touch is a roll away
    mid = target / 2
    behind = routine._safe(0.0, target)  # where the move keeps the stage
    cmd = free_ticks(routine, mid, behind, 4)
    assert cmd.roll == target  # free and behind the surface: the roll goes on
    bow = 1.2 * TOUCH_BOW * routine.settings.touch_strain  # the surface met mid-roll
    for _ in range(2):
        cmd = routine.step(obs(mid, behind, bow))
    assert isinstance(cmd, Command)
    assert cmd.roll == mid  # held where it is
    assert cmd.advance <= behind - routine.settings.clearance  # backing off along the ray
    cmd = free_ticks(routine, mid, cmd.advance, 4)
    assert cmd.roll == target  # free again: the roll goes on


def test_a_pattern_past_its_budget_is_a_geometric_answer() -> None:
    """Moving between touches with the surface never reached: once the budget (from the drive's
    limits) is spent, the routine answers with the reason instead of a command."""
    routine, target = moving_routine()
    budget = routine.settings.budget
    assert math.isfinite(budget)
    assert 0 < budget < 60.0
    first = routine.step(obs(target / 2, CONTACT - 5e-3, 0.0, t=1.0))
    assert isinstance(first, Command)
    late = routine.step(obs(target / 2, CONTACT - 5e-3, 0.0, t=1.0 + budget + 0.1))
    assert isinstance(late, str)
    assert "budget" in late
