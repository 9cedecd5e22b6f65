"""Jogging from a remote controller: a gamepad's ``sensor_msgs/Joy`` axes and buttons as the jog
model's keys, and the hold when the commands stop coming. Pure logic on
:class:`robot.teleop.Teleop`: the same guards, limits and emergency stop as the keyboard
(``palpate ros`` feeds it)::

    pad = JoyMapping()
    for key in pad.keys(axes, buttons):   # each Joy message
        model.press(key)
    servo_to(model, 0.004, None)           # a joint goal (servo_jp): advance 4 mm, roll as is
    hold(model, "no command for 0.5 s")    # the commands went quiet
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

from ..drive import JointState
from .interface import ESTOP_KEY
from .model import LATCHED, Teleop


@dataclass
class JoyMapping:
    """A gamepad as the ``joy`` node reports it (an Xbox-style layout by default): the left stick
    up/down advances/retracts, left/right rolls (left is +1 on the stick's axis), button A is the
    emergency stop and B re-arms. A stick past ``deadzone`` presses its key once per message (so
    the goal moves while messages come); a button presses on its rising edge only."""

    advance_axis: int = 1
    roll_axis: int = 0
    estop_button: int = 0
    rearm_button: int = 1
    deadzone: float = 0.5
    _held: set[int] = field(default_factory=set)

    def keys(self, axes: Sequence[float], buttons: Sequence[int]) -> list[str]:
        """The key names one Joy message presses (the emergency stop first)."""
        pressed = {b for b, v in enumerate(buttons) if v}
        rising, self._held = pressed - self._held, pressed
        keys = [ESTOP_KEY] if self.estop_button in rising else []
        if self.rearm_button in rising:
            keys.append("r")
        advance = _axis(axes, self.advance_axis)
        roll = _axis(axes, self.roll_axis)
        if abs(advance) > self.deadzone:
            keys.append("up" if advance > 0 else "down")
        if abs(roll) > self.deadzone:
            keys.append("left" if roll > 0 else "right")
        return keys


def _axis(axes: Sequence[float], index: int) -> float:
    return float(axes[index]) if 0 <= index < len(axes) else 0.0


def servo_to(model: Teleop, advance: float | None, roll: float | None) -> None:
    """A joint goal (m, rad; None: that joint as it is) through the jog's guards: refused
    while latched or before a reading, each joint within a step of where the robot is."""
    if model.state in LATCHED:
        model.message = f"{model.state.value}: re-arm before moving"
        return
    if model.obs is None or model.goal is None:
        model.message = "no reading from the drive yet"
        return
    if roll is not None and roll != model.goal.roll:
        model.roll_to(roll)
    if advance is not None and advance != model.goal.translation:
        model.advance_to(advance, 1.0 if advance > model.goal.translation else -1.0)


def hold(model: Teleop, why: str) -> None:
    """Stop where the robot is (its commands stopped coming): the goal becomes the last reading;
    a retraction, an emergency stop or a fault goes on as it was."""
    obs = model.obs
    if model.state in LATCHED or obs is None:
        return
    here = JointState(obs.roll, obs.advance)
    if model.goal is not None and model.goal != here:
        model.message = f"held: {why}"
    model.goal = here


__all__ = ["JoyMapping", "hold", "servo_to"]
