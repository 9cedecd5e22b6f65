"""What a teleop front end exchanges with the jog model: key names and the actions they map to,
the jog settings (step sizes, speeds, margins), the effects only the front end can carry out,
and the view it draws.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Literal

from ...config.schema import TubeConfig
from ..drive import JointState
from ..indentation import State

Action = Literal[
    "advance",
    "retract",
    "roll+",
    "roll-",
    "tube+",
    "tube-",
    "step+",
    "step-",
    "speed+",
    "speed-",
    "estop",
    "rearm",
    "save",
    "quit",
]

# Key names (what the terminal front end passes) -> actions. Arrow keys and vi keys both jog.
KEYMAP: dict[str, Action] = {
    "up": "advance",
    "k": "advance",
    "down": "retract",
    "j": "retract",
    "right": "roll+",
    "l": "roll+",
    "left": "roll-",
    "h": "roll-",
    "t": "tube+",
    "T": "tube-",
    "+": "step+",
    "=": "step+",
    "-": "step-",
    "]": "speed+",
    "[": "speed-",
    " ": "estop",
    "r": "rearm",
    "s": "save",
    "q": "quit",
}
ESTOP_KEY = " "
NAME_CHARS = re.compile(r"[A-Za-z0-9_.-]")
MAX_NAME = 40


@dataclass(frozen=True)
class JogSettings:
    """Step sizes (advance m, roll rad, chosen together), advance speeds (m/s) and margins."""

    steps: tuple[tuple[float, float], ...] = (
        (0.1e-3, math.radians(1.0)),
        (0.5e-3, math.radians(5.0)),
        (1e-3, math.radians(10.0)),
        (5e-3, math.radians(45.0)),
    )
    step_index: int = 2
    speeds: tuple[float, ...] = (0.5e-3, 1e-3, 2e-3, 5e-3)
    speed_index: int = 2
    travel_margin: float = 20e-6  # jogs stop this short of the travel-past-contact limit (m)
    position_tolerance: float = 15e-6  # m: "there" for the advance (about 3 encoder ticks)
    roll_tolerance: float = 2e-3  # rad

    def __post_init__(self) -> None:
        if not self.steps or not self.speeds:
            raise ValueError("teleop needs at least one step size and one speed")
        if not 0 <= self.step_index < len(self.steps):
            raise ValueError(f"step_index {self.step_index} outside 0..{len(self.steps) - 1}")
        if not 0 <= self.speed_index < len(self.speeds):
            raise ValueError(f"speed_index {self.speed_index} outside 0..{len(self.speeds) - 1}")


@dataclass(frozen=True)
class Effect:
    """Something only the front end can do: quit, save a target, re-enable torque after a
    fault (``recover``), or mount another tube in a simulated world (``tube``)."""

    kind: Literal["quit", "save", "recover", "tube"]
    value: str = ""


@dataclass(frozen=True)
class TeleopView:
    """Everything the screen shows, in SI; None where nothing was measured yet."""

    state: State
    tube: TubeConfig
    roll: float | None
    advance: float | None
    goal: JointState | None
    step: tuple[float, float]
    speed: float
    exposed_length: float | None
    tube_tip: tuple[float, float, float] | None
    tangent: tuple[float, float, float] | None
    sensor_tip: tuple[float, float, float] | None
    strains: tuple[float, ...]
    strain_norm: float
    strain_limit: float
    contact: bool
    buckled: bool
    travel_past_contact: float | None
    travel_limit: float
    stream_age: float
    fault: str | None
    message: str
    prompt: str | None
    tip_force: float | None = None  # N, the tip force grating's load (None: no tip grating)
    gate: bool | None = None  # the ventilator's breath hold now (None: no gate seen this session)
