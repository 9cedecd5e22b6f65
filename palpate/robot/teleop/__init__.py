"""Teleoperation: jog roll, advance and tube by key, within the limits of a scripted trial.

Pure logic, no terminal and no hardware, so it is unit-tested like the state machine: the
terminal front end (``palpate teleop``) turns key codes into key names, calls :meth:`Teleop.press`
for each and :meth:`Teleop.step` once per control tick with the rig's
:class:`~robot.indentation.Observation`, sends the returned
:class:`~robot.indentation.Command` to the same :class:`robot.rig.ServoFbgRig` a trial uses, and
draws :meth:`Teleop.view` (the screen's text belongs to the application).

- :mod:`robot.teleop.interface`: key map, jog settings, effects and the view;
- :mod:`robot.teleop.model`: the jog model, its limits, guards and states (the safety rules).
"""

from __future__ import annotations

from .interface import (
    ESTOP_KEY,
    KEYMAP,
    Action,
    Effect,
    JogSettings,
    TeleopView,
)
from .model import LATCHED, Teleop

__all__ = [
    "ESTOP_KEY",
    "KEYMAP",
    "LATCHED",
    "Action",
    "Effect",
    "JogSettings",
    "Teleop",
    "TeleopView",
]
