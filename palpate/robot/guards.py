"""What the indentation machine watches each tick, and the limits that stop a trial: one
:class:`Observation` of the rig, the :class:`Guards`, and :func:`limit_violation`, which the
state machine (``robot.indentation``) and teleoperation (``robot.teleop``) share."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from palpate.wire.frame import Frame

STATE_TIMEOUT = 60.0  # s in any one state (a guard: a state that never ends is a fault)


@dataclass(frozen=True)
class Guards:
    """Limits that stop a trial. Exceeding any of them is a FAULT with the guard named."""

    max_travel_past_contact: float = 2.5e-3  # m; the beam or the tissue is at risk beyond
    strain_limit: float = 5e-3  # fiber strain (dimensionless); protects the fiber
    # s without a fresh FBG frame before the motion holds (the strains are stale: nothing is
    # decided on them); it resumes when frames come again, and the gap is recorded
    stream_timeout: float = 0.1
    stream_lost: float = 1.0  # s without a frame in a contact phase: the stream is lost, a FAULT
    state_timeout: float = STATE_TIMEOUT  # s in any one state
    early_contact_margin: float = 0.5e-3  # contact this much before the plan is "unexpected"
    bus_grace: float = 0.5  # s of lost servo replies tolerated while retracting (goals still go)
    max_twist: float | None = None  # rad, inner vs outer roller gear; None: not watched


@dataclass(frozen=True)
class Observation:
    t: float  # s
    advance: float  # m, stage position from the translation servo's encoder
    roll: float  # rad, outer roll from its encoder
    strains: tuple[float, ...]  # grating-average strains of the used gratings
    contact: bool  # the contact event (force scale / camera / FBG), as the rig reports it
    stream_age: float = 0.0  # s since the last good FBG frame
    servo_fault: str | None = None  # a fault the servo bus reported, if any
    bus_lost: bool = False  # servo_fault is a transport failure (no or garbled replies)
    abort: bool = False  # the operator pressed stop
    twist: float = 0.0  # rad, inner roller gear's roll minus the outer's (the sensor's twist)
    tip_force: float | None = None  # N, the tip force grating's load (None: no tip grating)
    # s since the servos last answered: > 0 on a tick whose read was missed (the joints are
    # then the last ones read; the rig holds the motion until the bus answers again)
    joints_age: float = 0.0
    # the ventilator's breath-hold gate in the newest frame (status bit 6); None: no frame yet
    gate: bool | None = None
    # an ECG monitor's R-wave pulse in a frame of this tick (status bit 7): the heart's beat
    beat: bool = False
    # the newest FBG frame as the board sent it (its peak wavelengths; None: none yet)
    frame: Frame | None = field(default=None, compare=False, repr=False)

    @property
    def measured_advance(self) -> float:
        """The stage advance as the record keeps it: NaN on a tick whose read was missed."""
        return self.advance if self.joints_age == 0.0 else math.nan


def limit_violation(guards: Guards, obs: Observation, x_contact: float | None) -> str | None:
    """Why the fiber-strain or travel-past-contact guard trips on ``obs``, or None.

    One function for the state machine and for teleoperation (``robot.teleop``), so a jog is
    held to exactly the limits of a scripted trial. ``x_contact`` is the stage position at
    contact (m), None while the sensor is free.
    """
    peak = max((abs(s) for s in obs.strains), default=0.0)
    if peak > guards.strain_limit:
        return f"fiber strain {peak * 1e6:.0f} ue over the limit {guards.strain_limit * 1e6:.0f} ue"
    if guards.max_twist is not None and abs(obs.twist) > guards.max_twist:
        return (
            f"sensor twist {math.degrees(obs.twist):.2f} deg (inner vs outer roller gear) over "
            f"the {math.degrees(guards.max_twist):.2f} deg bound"
        )
    if x_contact is not None:
        past = obs.advance - x_contact
        if past > guards.max_travel_past_contact:
            return f"travel past contact {past * 1e3:.2f} mm over the limit"
    return None
