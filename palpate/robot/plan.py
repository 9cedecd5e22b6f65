"""What the indentation machine (``robot.indentation``) is given and gives back: its states and
how a trial ends, the plan, the commands, the transitions it logs and the marks the estimator
reads. Plain data: the trial loop, the log and the estimate use them without the machine."""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import Protocol

from ..estimation.pose.heartbeat import QUIET
from .guards import Observation
from .probe_result import ProbeResult


class State(enum.StrEnum):
    """The machine's states; a trial's ending is one of them (a ``StrEnum``: it equals its value,
    ``State.DONE == "done"``, and a log or JSON writes the value)."""

    IDLE = "idle"
    HOMING = "homing"
    POSITIONING = "positioning"
    WAITING = "waiting"
    PROBING = "probing"
    APPROACH = "approach"
    CONTACT = "contact"
    INDENTING = "indenting"
    BUCKLED = "buckled"
    HOLDING = "holding"
    RETRACTING = "retracting"
    DONE = "done"
    FAULT = "fault"
    ABORTED = "aborted"
    UNREACHABLE = "unreachable"
    SKIPPED = "skipped"  # never entered: the bench session's ending for a trial it did not start


TERMINAL = frozenset({State.DONE, State.FAULT, State.ABORTED, State.UNREACHABLE})
PLANNED_ENDS = frozenset({State.DONE, State.UNREACHABLE})  # torque stays on: nothing went wrong


@dataclass(frozen=True)
class TrialPlan:
    """Where to go: from inverse kinematics and the campaign (SI: m, rad, m/s)."""

    roll: float
    contact_advance: float  # advance where the tip sphere is expected to touch (m)
    home_advance: float = 0.0
    standoff: float = 2e-3  # stop this far before the expected contact, then approach slowly
    approach_window: float = 3e-3  # no contact this far past the expected contact -> fault
    post_buckling_travel: float = 0.3e-3  # keep indenting after detection, for the record
    fast_speed: float = 5e-3
    approach_speed: float = 1e-3
    indent_speed: float = 0.5e-3
    roll_tolerance: float = 2e-3
    position_tolerance: float = 5e-6
    hold_time: float = 0.0  # s at rest after the post-buckling travel (a creep test); 0: none
    # wait at the stand-off for a breath hold (the ventilator's gate, Observation.gate) that
    # began at most ``gate_fresh`` s before, indent within it; a hold that ends first retracts
    # and waits for the next, ``hold_retries`` times at most (robot.body)
    gated: bool = False
    gate_fresh: float = 1.0
    hold_retries: int = 2
    # once an ECG's R waves are seen: the indentation at this speed at most, the approach at full
    # speed to ``heart_margin`` before the expected surface (robot.body)
    heart_speed: float = 0.1e-3
    heart_margin: float = 1e-3
    # the share of the R-R interval after an R wave in which the buckling detector reads ticks
    # while the heart beats (robot.body: mid-diastole)
    heart_quiet: tuple[float, float] = QUIET
    # quiet windows in contact before a buckle outside them counts; held still after buckling
    heart_touches: int = 4
    heart_windows: int = 2

    def retract_goal(self, first_touch: float | None) -> float:
        """Home, or further back if the tissue was touched (at ``first_touch``, m) where the plan
        did not expect it: never end a retraction still touching."""
        if first_touch is None:
            return self.home_advance
        return min(self.home_advance, first_touch - self.standoff)


@dataclass(frozen=True)
class Command:
    advance: float  # goal, m
    roll: float  # goal, rad
    speed: float  # m/s for the advance
    torque: bool = True
    rezero: bool = False  # take the strain zero again on the frames of the last ticks at rest


class Prober(Protocol):
    """The probing step (``robot.probing.ProbeRoutine``): each tick a command, then its result
    (or a ``str``: why it failed)."""

    def step(self, obs: Observation) -> Command | ProbeResult | str: ...


@dataclass(frozen=True)
class Transition:
    t: float
    source: State
    target: State
    reason: str
    advance: float
    strains: tuple[float, ...]


@dataclass
class TrialMarks:
    """What the estimator needs: encoder values at contact and at detected buckling."""

    x_contact: float | None = None
    x_buckling: float | None = None
    t_contact: float | None = None
    t_buckling: float | None = None
    strains_at_buckling: tuple[float, ...] = ()
    reason: str = ""

    def buckled(self, t: float, advance: float, strains: tuple[float, ...]) -> None:
        """Mark buckling detected at ``t`` (s), ``advance`` (m), with these strains."""
        self.x_buckling, self.t_buckling, self.strains_at_buckling = advance, t, strains
