"""The indentation state machine: explicit states, guards, and a log line for every transition.

It is pure logic: each control tick the trial loop hands it an :class:`Observation` (stage
position from the servo encoder, the grating strains, the contact event, health of the streams)
and gets back a :class:`Command` (goal advance and roll, and the speed to get there). It never
touches hardware, so the same machine runs on the bench, on the emulators and in tests.

States and the normal path::

    IDLE -> HOMING -> POSITIONING [-> WAITING] -> APPROACH -> CONTACT -> INDENTING -> BUCKLED
         [-> HOLDING] -> RETRACTING -> DONE

With ``TrialPlan.gated`` the machine waits at the stand-off (WAITING) for a breath hold that
has just begun (``robot.body``), then approaches and indents within it; a hold that ends first
retracts and waits for the next (the tissue moves again), and after ``hold_retries`` such holds
the trial ends DONE with no estimate (``estimation.verdict.HOLDS_RAN_OUT``). With an ECG's R
waves the tip indents slowly and buckling is judged in the heart's quiet phase (``robot.body``).

With ``TrialPlan.hold_time`` > 0 the stage then stands still that long: the buckled beam is
nearly a constant-force spring, so the hold is a creep test the gratings record
(``estimation.relaxation``); a contact phase, every guard applies.

A stale FBG stream (``Guards.stream_timeout``) in a contact phase holds the motion and reports
the gap once frames come again (``on_gap``); a stream silent ``Guards.stream_lost`` faults.

With a ``prober`` (``robot.probing``) the first arrival at the stand-off goes to PROBING
instead: light touches around the plan, a fitted surface, and the pose orthogonal to it, which
replaces the plan's roll and contact advance (POSITIONING again, the strain zero taken again at
the new roll, then APPROACH). Where no pose is within the tolerances the machine retracts and
ends in UNREACHABLE before it indents: the trial's verdict, not a fault of the hardware.

FAULT (a guard tripped: retract, then stop) and ABORTED (operator stop) are reachable from every
state. A fault always ends with the stage retracted to the home advance when the drive still
answers; the trial record is closed with the reason.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass, field

from ..estimation.detect.buckling import BucklingDetector
from ..estimation.reach import NO_BUCKLING
from ..estimation.verdict import HOLDS_RAN_OUT
from .body import STANDOFF_HINT, BodyWatch
from .guards import STATE_TIMEOUT, Guards, Observation, limit_violation
from .plan import PLANNED_ENDS, TERMINAL, Command, Prober, State, Transition, TrialMarks, TrialPlan
from .probe_result import ProbeResult
from .rest_check import RestCheck

# the guards' and the plan's names, re-exported: the machine's interface is read from here
__all__ = [
    "PLANNED_ENDS",
    "STATE_TIMEOUT",
    "TERMINAL",
    "Command",
    "Guards",
    "Observation",
    "Prober",
    "State",
    "Transition",
    "TrialMarks",
    "TrialPlan",
    "limit_violation",
]

REZERO_SETTLE_TICKS = 10  # ticks at rest before the strain zero is taken again
WAIT_CONFIRM = 3  # ticks a contact holds while WAITING before the rest check takes it
AT_REST = frozenset({State.HOMING, State.POSITIONING, State.WAITING})  # no tissue: a RestCheck
GATED = frozenset({State.APPROACH, State.CONTACT, State.INDENTING, State.BUCKLED, State.HOLDING})
CONTACT_PHASE = GATED | {State.PROBING}  # the sensor may touch the tissue: the stream must live


@dataclass
class IndentationMachine:
    """One trial's controller. Call :meth:`step` once per control tick."""

    plan: TrialPlan
    guards: Guards
    detector: BucklingDetector
    on_transition: Callable[[Transition], None] = lambda tr: None
    # a stale stream's gap, once frames come again: (start s, duration s, the state it held)
    on_gap: Callable[[float, float, State], None] = lambda t, d, s: None
    prober: Callable[[TrialPlan], Prober] | None = None  # builds the probing step from the plan
    state: State = State.IDLE
    marks: TrialMarks = field(default_factory=TrialMarks)
    probe: ProbeResult | None = None  # what probing found, once it has
    _probing: Prober | None = None
    _settle: int = -1  # ticks at rest so far before the re-zero; -1: none pending
    _entered: float = 0.0
    _last_command: Command | None = None
    _first_touch: float | None = None  # advance at the first contact event, planned or not
    _lost_since: float | None = None  # time the servo replies were lost while retracting
    _rest: RestCheck = field(default_factory=lambda: RestCheck(REZERO_SETTLE_TICKS))
    _body: BodyWatch = field(default_factory=BodyWatch)  # the breath-hold gate, the heart
    _retry: bool = False  # retracting to wait for the next breath hold
    _contact_ticks: int = 0  # successive ticks with a contact
    _stale_since: float | None = None  # when the stream went stale in a contact phase
    # how the trial will end once retracted: set with the reason, never read back from its text
    ending: State = State.FAULT

    def __post_init__(self) -> None:
        hold, timeout = self.plan.hold_time, self.guards.state_timeout
        if not (math.isfinite(hold) and 0.0 <= hold < timeout):
            raise ValueError(f"hold_time must be >= 0 s and below {timeout:g} s, got {hold!r}")

    # -- public -------------------------------------------------------------------------------
    @property
    def stream_held(self) -> bool:
        """The motion holds for a stale stream: this tick's strains are old (not a record's)."""
        return self._stale_since is not None

    @property
    def finished(self) -> bool:
        return self.state in TERMINAL

    def start(self, t: float) -> None:
        if self.state is not State.IDLE:
            raise RuntimeError(f"start() in state {self.state.value}; a machine runs one trial")
        self.detector.reset()
        self._go(State.HOMING, t, "start", math.nan, ())

    def step(self, obs: Observation) -> Command:
        """Advance the machine by one tick and return the goal to send to the drive."""
        if self.state is State.IDLE:
            self.start(obs.t)
        self._body.see(obs)
        if not self.finished:
            self._check_guards(obs)
        cmd = self._held(obs) or self._stream_hold(obs) or _HANDLERS[self.state](self, obs)
        self._last_command = cmd
        return cmd

    def abort(self, t: float, reason: str) -> None:
        """Operator stop: go to RETRACTING at once, ending in ABORTED."""
        if not self.finished:
            self.marks.reason, self.ending = f"aborted: {reason}", State.ABORTED
            self._go(State.RETRACTING, t, self.marks.reason, math.nan, ())

    # -- guards -------------------------------------------------------------------------------
    def _check_guards(self, obs: Observation) -> None:
        if obs.abort and self.ending is not State.ABORTED:
            self.abort(obs.t, "operator stop")
            return
        if obs.contact and self._first_touch is None and math.isfinite(obs.advance):
            self._first_touch = obs.advance
        if self.state is State.RETRACTING:
            if obs.servo_fault is None:
                self._lost_since = None
                return
            if obs.bus_lost:
                # Replies lost, but goals still reach the servos: keep pulling back (away from
                # the tissue) for a grace period in case the bus comes back.
                if self._lost_since is None:
                    self._lost_since = obs.t
                if obs.t - self._lost_since < self.guards.bus_grace:
                    return
            # Retraction itself failed: stop where we are; the runner releases torque.
            self._fault(obs, f"servo fault while retracting: {obs.servo_fault}", retract=False)
            return
        if obs.servo_fault is not None:
            # Stop and retract: the runner clears the fault (reboot) before it moves again.
            self._fault(obs, f"servo fault: {obs.servo_fault}")
            return
        if obs.t - self._entered > self.guards.state_timeout:
            self._fault(obs, f"timeout in {self.state.value} after {self.guards.state_timeout:g} s")
            return
        if self.state in CONTACT_PHASE and obs.stream_age > self.guards.stream_lost:
            self._fault(obs, f"FBG stream lost ({obs.stream_age * 1e3:.0f} ms without a frame)")
            return
        if self.plan.gated and self.state in GATED and not obs.gate:
            self._hold_ended(obs)
            return
        violation = limit_violation(self.guards, obs, self.marks.x_contact)
        if violation is not None:
            self._fault(obs, violation)
            return
        if self._waited_contact(obs) and self.state in AT_REST and not self._rest.seen():
            hint = STANDOFF_HINT if self.state is State.WAITING else ""
            self._fault(obs, f"unexpected contact during {self.state.value} ({self._rest}){hint}")

    def _waited_contact(self, obs: Observation) -> bool:
        """A contact at rest; while WAITING (a breath cycle at most: thousands of frames, where
        a zero's noise crosses the threshold on a frame or two) one held WAIT_CONFIRM ticks."""
        self._contact_ticks = self._contact_ticks + 1 if obs.contact else 0
        if self.state is not State.WAITING:
            return obs.contact
        return self._contact_ticks >= WAIT_CONFIRM

    def _hold_ended(self, obs: Observation) -> None:
        """Retract to wait for the next breath hold; past ``hold_retries`` of them, no estimate."""
        why, body = f"the breath hold ended during {self.state.value}", self._body
        body.failed_holds += 1
        if body.failed_holds > self.plan.hold_retries:
            self.marks.reason, self.ending = f"{HOLDS_RAN_OUT} ({why})", State.DONE
            self._go(State.RETRACTING, obs.t, self.marks.reason, obs.advance, obs.strains)
            return
        self._retry = True
        self._go(State.RETRACTING, obs.t, f"{why}: to the next", obs.advance, obs.strains)

    def _fault(self, obs: Observation, reason: str, *, retract: bool = True) -> None:
        self.marks.reason, self.ending = reason, State.FAULT
        if retract:
            self._go(State.RETRACTING, obs.t, f"fault: {reason}", obs.advance, obs.strains)
        else:
            self._go(State.FAULT, obs.t, reason, obs.advance, obs.strains)

    # -- states -------------------------------------------------------------------------------
    def _go(
        self, target: State, t: float, reason: str, advance: float, strains: tuple[float, ...]
    ) -> None:
        tr = Transition(
            t=t, source=self.state, target=target, reason=reason, advance=advance, strains=strains
        )
        self.state = target
        self._entered = t
        self.on_transition(tr)

    def _held(self, obs: Observation) -> Command | None:
        """Hold still while a :class:`RestCheck` runs (re-zeroing on its last tick)."""
        rezero = self._rest.hold(self.state in AT_REST)
        return None if rezero is None else Command(obs.advance, obs.roll, 0.0, rezero=rezero)

    def _stream_hold(self, obs: Observation) -> Command | None:
        """Hold still while the stream is stale in a contact phase; report the gap after."""
        if self.state in CONTACT_PHASE and obs.stream_age > self.guards.stream_timeout:
            if self._stale_since is None:  # a gap starts at its last frame (t 0.0 is one)
                self._stale_since = obs.t - obs.stream_age
            return Command(obs.advance, obs.roll, 0.0)
        if self._stale_since is not None:
            since, self._stale_since = self._stale_since, None
            if not self.finished:
                self.on_gap(since, obs.t - since, self.state)
        return None

    def _hold(self, obs: Observation) -> Command:
        return Command(advance=obs.advance, roll=obs.roll, speed=0.0, torque=True)

    def _homing(self, obs: Observation) -> Command:
        p = self.plan
        if abs(obs.advance - p.home_advance) <= p.position_tolerance:
            self._go(State.POSITIONING, obs.t, "at home", obs.advance, obs.strains)
        return Command(p.home_advance, obs.roll, p.fast_speed)

    def _positioning(self, obs: Observation) -> Command:
        p = self.plan
        target = p.contact_advance - p.standoff
        at_roll = abs(obs.roll - p.roll) <= p.roll_tolerance
        if at_roll and abs(obs.advance - target) <= p.position_tolerance:
            if self.prober is not None and self.probe is None:
                self._probing = self.prober(p)
                self._go(State.PROBING, obs.t, "at stand-off: probing", obs.advance, obs.strains)
                return self._probe_step(obs)
            if self._settle >= 0:  # re-zero the strains at the new roll, at rest
                self._settle += 1
                rezero = self._settle > REZERO_SETTLE_TICKS
                self._settle = -1 if rezero else self._settle
                return Command(target, p.roll, 0.0, rezero=rezero)
            if p.gated:
                self._go(State.WAITING, obs.t, "at stand-off", obs.advance, obs.strains)
                return self._waiting(obs)
            self._go(State.APPROACH, obs.t, "at stand-off", obs.advance, obs.strains)
            return Command(target, p.roll, p.approach_speed)
        # Roll first with the sensor back, then advance: never sweep the tip sideways near tissue.
        goal = target if at_roll else min(obs.advance, target)
        return Command(goal, p.roll, p.fast_speed)

    def _waiting(self, obs: Observation) -> Command:
        """Hold at the stand-off until a breath hold begins (its gate rose just now)."""
        p = self.plan
        target = p.contact_advance - p.standoff
        if self._body.hold_began(obs, p.gate_fresh):
            self._go(State.APPROACH, obs.t, "breath hold", obs.advance, obs.strains)
            return Command(target, p.roll, p.approach_speed)
        return Command(target, p.roll, 0.0)

    def _approach(self, obs: Observation) -> Command:
        p, g = self.plan, self.guards
        if obs.contact:
            if obs.advance < p.contact_advance - p.standoff - g.early_contact_margin:
                self._fault(obs, "contact earlier than planned")
                return self._hold(obs)
            self.marks.x_contact = obs.advance
            self.marks.t_contact = obs.t
            self._go(State.CONTACT, obs.t, "contact event", obs.advance, obs.strains)
            return self._hold(obs)
        limit = p.contact_advance + p.approach_window
        if obs.advance >= limit - p.position_tolerance:
            self._fault(
                obs, f"no contact within {p.approach_window * 1e3:.1f} mm past the expected surface"
            )
            return self._hold(obs)
        goal, speed = self._body.approach(p, obs.advance) or (limit, p.approach_speed)
        return Command(goal, p.roll, speed)

    def _probe_step(self, obs: Observation) -> Command:
        assert self._probing is not None  # set on entering PROBING
        out = self._probing.step(obs)
        if isinstance(out, Command):
            return out
        if isinstance(out, str):  # no surface where one must be: a geometric answer
            return self._unreachable(obs, out)
        self.probe = out
        self.plan = dataclasses.replace(
            self.plan, roll=out.roll, contact_advance=out.contact_advance
        )
        if not out.reachable:
            return self._unreachable(obs, out.reason)
        self._settle = 0
        self._go(State.POSITIONING, obs.t, f"probed: {out.reason}", obs.advance, obs.strains)
        return self._positioning(obs)

    def _unreachable(self, obs: Observation, why: str) -> Command:
        self.marks.reason, self.ending = f"unreachable: {why}", State.UNREACHABLE
        self._go(State.RETRACTING, obs.t, self.marks.reason, obs.advance, obs.strains)
        return Command(self.plan.retract_goal(self._first_touch), obs.roll, self.plan.fast_speed)

    def _contact(self, obs: Observation) -> Command:
        self.detector.reset()
        self._body.mark()
        self._go(State.INDENTING, obs.t, "indenting", obs.advance, obs.strains)
        return self._indent_goal(obs)

    def _indent_goal(self, obs: Observation) -> Command:
        assert self.marks.x_contact is not None  # set on entering CONTACT: the window ends short
        window = self.guards.max_travel_past_contact - self.plan.position_tolerance  # of the guard
        speed = self._body.indent_speed(self.plan)
        return Command(self.marks.x_contact + window, self.plan.roll, speed)

    def _indenting(self, obs: Observation) -> Command:
        if self._body.reads(obs, self.plan) and self.detector.update(
            obs.strains, obs.advance, obs.tip_force
        ):
            self.marks.buckled(obs.t, obs.advance, obs.strains)
            self._body.mark()
            self._go(State.BUCKLED, obs.t, "buckling detected", obs.advance, obs.strains)
            return self._indent_goal(obs)
        cmd = self._indent_goal(obs)
        if obs.advance >= cmd.advance - self.plan.position_tolerance:
            # The whole travel window used up without buckling (tissue below the sensor's range,
            # a compliant tube tip): an answer, not a fault (the verdict bounds the modulus).
            travel = f"{self.guards.max_travel_past_contact * 1e3:.2f} mm"
            self.marks.reason = f"{NO_BUCKLING}: travel past contact reached the {travel} limit"
            return self._complete(obs, self.marks.reason)
        return cmd

    def _post_goal(self, obs: Observation) -> float:
        """The post-buckling record's end, never past the travel window (nor its guard)."""
        assert self.marks.x_buckling is not None
        goal = self.marks.x_buckling + self._body.post_travel(self.plan)
        return min(goal, self._indent_goal(obs).advance)

    def _buckled(self, obs: Observation) -> Command:
        goal, settled = self._post_goal(obs), self._body.settled(obs.t, self.plan)
        if obs.advance >= goal - self.plan.position_tolerance and settled:
            if self.plan.hold_time <= 0:
                return self._complete(obs, "post-buckling record complete")
            why = "post-buckling record complete: holding"
            self._go(State.HOLDING, obs.t, why, obs.advance, obs.strains)
        return Command(goal, self.plan.roll, self.plan.indent_speed)

    def _holding(self, obs: Observation) -> Command:
        if obs.t - self._entered >= self.plan.hold_time - 1e-9:  # the clock sums its ticks
            return self._complete(obs, f"hold of {self.plan.hold_time:g} s complete")
        return Command(self._post_goal(obs), self.plan.roll, self.plan.indent_speed)

    def _complete(self, obs: Observation, why: str) -> Command:
        self.marks.reason, self.ending = self.marks.reason or "completed", State.DONE
        self._go(State.RETRACTING, obs.t, why, obs.advance, obs.strains)
        return Command(
            self.plan.retract_goal(self._first_touch), self.plan.roll, self.plan.fast_speed
        )

    def _retracting(self, obs: Observation) -> Command:
        p = self.plan
        goal = p.retract_goal(self._first_touch)
        if abs(obs.advance - goal) <= p.position_tolerance:
            if self._retry:  # the attempt's marks go: the next hold's are the trial's
                self._retry, self.marks = False, TrialMarks()
                self._go(State.POSITIONING, obs.t, "to the next breath hold", goal, obs.strains)
                return Command(goal, obs.roll, 0.0)
            self._go(
                self.ending, obs.t, f"retracted ({self.marks.reason})", obs.advance, obs.strains
            )
            return self._terminal(obs)
        return Command(goal, obs.roll, p.fast_speed)

    def _terminal(self, obs: Observation) -> Command:
        return Command(obs.advance, obs.roll, 0.0, torque=self.state in PLANNED_ENDS)


_STEPS = frozenset(State) - TERMINAL - {State.IDLE, State.PROBING, State.SKIPPED}  # "_<value>"
_HANDLERS: dict[State, Callable[[IndentationMachine, Observation], Command]] = {
    State.PROBING: IndentationMachine._probe_step,
    **dict.fromkeys(TERMINAL, IndentationMachine._terminal),
    **{s: getattr(IndentationMachine, f"_{s.value}") for s in _STEPS},
}
