"""The jog model: :class:`Teleop` turns key names into goals, within the limits of a scripted
trial.

Safety, the same rules as a scripted trial:

- goals are clamped to the drive's translation and roll limits (``DriveConfig``);
- the fiber-strain and travel-past-contact guards are
  :func:`robot.indentation.limit_violation`, the function the state machine uses; a jog stops
  short of the travel limit, and a guard that trips anyway stops and retracts (a fault), as in a
  trial; losing the FBG stream in contact does too, and advancing without a stream is refused;
- no runaway: a press moves the goal one step, and never more than one step ahead of where the
  stage is, so keys queued or held move the stage only while they keep coming;
- the emergency stop (space) stops and retracts to the home translation at once, then holds
  there until re-armed (``r``); a fault ends with torque off;
- no roll while in contact (it would sweep the tip sideways in the tissue), no tube change unless
  the sensor is back inside the tube.

States are the state machine's names: ``idle`` (holding), ``positioning`` (moving to the jog
goal), ``retracting``, ``aborted`` (after an emergency stop), ``fault``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

from ...config.schema import DriveConfig, TubeConfig
from ...config.targets import TargetConfig
from ...estimation.detect.buckling import BucklingDetector
from .. import kinematics
from ..drive import JointState, RollerGearDrive
from ..indentation import (
    Command,
    Guards,
    Observation,
    State,
    limit_violation,
)
from .interface import (
    ESTOP_KEY,
    KEYMAP,
    MAX_NAME,
    NAME_CHARS,
    Effect,
    JogSettings,
    TeleopView,
)

LATCHED = frozenset({State.RETRACTING, State.ABORTED, State.FAULT})


@dataclass
class Teleop:
    """The jog model. Feed it keys (:meth:`press`) and observations (:meth:`step`)."""

    drive: DriveConfig
    tubes: Sequence[TubeConfig]
    guards: Guards
    detector: BucklingDetector
    tube_name: str | None = None
    settings: JogSettings = field(default_factory=JogSettings)
    fast_speed: float | None = None  # m/s for retraction; None: the drive's max speed
    state: State = State.IDLE
    goal: JointState | None = None
    obs: Observation | None = None
    x_contact: float | None = None
    buckled: bool = False
    gated: bool = False  # a breath-hold gate was seen open this session (the screen shows it)
    fault: str | None = None
    message: str = "ready"
    prompt: str | None = None

    def __post_init__(self) -> None:
        if not self.tubes:
            raise ValueError("teleop needs at least one tube")
        names = [t.name for t in self.tubes]
        name = self.tube_name if self.tube_name is not None else names[0]
        if name not in names:
            raise ValueError(f"no tube named {name!r}; known: {names}")
        self._tube_index = names.index(name)
        self._limits = RollerGearDrive(self.drive)
        self._step_index = self.settings.step_index
        self._speed_index = self.settings.speed_index
        self._estop = False

    # -- settings -----------------------------------------------------------------------------
    @property
    def tube(self) -> TubeConfig:
        return self.tubes[self._tube_index]

    @property
    def step_size(self) -> tuple[float, float]:
        """(advance m, roll rad) moved by one press."""
        return self.settings.steps[self._step_index]

    @property
    def speed(self) -> float:
        """Advance speed (m/s) of jogs, never above the drive's."""
        return min(self.settings.speeds[self._speed_index], self.drive.max_speed)

    @property
    def home(self) -> float:
        """Where an emergency stop retracts to: the drive's home translation (m)."""
        return self._limits.home.translation

    # -- keys ---------------------------------------------------------------------------------
    def press(self, key: str) -> Effect | None:
        """Handle one key (a name: ``"up"``, ``"k"``, ``" "``, ``"enter"``, ...)."""
        if key == ESTOP_KEY:  # works everywhere, also while typing a name
            self.prompt = None
            self.emergency_stop()
            return None
        if self.prompt is not None:
            return self._prompt_key(key)
        action = KEYMAP.get(key)
        if action is None:
            return None
        if action == "quit":
            return Effect("quit")
        if action == "save":
            return self._begin_save()
        if action == "rearm":
            return self._rearm()
        if action in ("step+", "step-", "speed+", "speed-"):
            self._adjust(action)
            return None
        if self.state in LATCHED:
            self.message = f"{self.state.value}: press r to re-arm before moving"
            return None
        if self.obs is None or self.goal is None:
            self.message = "no reading from the drive yet"
            return None
        if action in ("advance", "retract"):
            self._jog_advance(1.0 if action == "advance" else -1.0)
        elif action in ("roll+", "roll-"):
            self._jog_roll(1.0 if action == "roll+" else -1.0)
        else:
            return self._change_tube(1 if action == "tube+" else -1)
        return None

    def emergency_stop(self) -> None:
        """Stop and retract to the home translation, then hold (state ``aborted``)."""
        if self.state is State.FAULT:
            self.message = "torque is off after a fault: nothing to stop (r re-arms)"
            return
        self._estop = True
        self._go_retract("EMERGENCY STOP")

    def _adjust(self, action: str) -> None:
        s = self.settings
        if action == "step+":
            self._step_index = min(self._step_index + 1, len(s.steps) - 1)
        elif action == "step-":
            self._step_index = max(self._step_index - 1, 0)
        elif action == "speed+":
            self._speed_index = min(self._speed_index + 1, len(s.speeds) - 1)
        else:
            self._speed_index = max(self._speed_index - 1, 0)
        adv, roll = self.step_size
        self.message = (
            f"step {adv * 1e3:.3g} mm / {math.degrees(roll):.3g} deg, "
            f"speed {self.speed * 1e3:.3g} mm/s"
        )

    def _jog_advance(self, sign: float) -> None:
        assert self.goal is not None
        self.advance_to(self.goal.translation + sign * self.step_size[0], sign)

    def advance_to(self, goal: float, sign: float) -> None:
        """The advance goal to ``goal`` (``sign``: its way) within the guards and a step."""
        assert self.obs is not None and self.goal is not None  # noqa: PT018
        obs, step = self.obs, self.step_size[0]
        if sign > 0 and obs.stream_age > self.guards.stream_timeout:
            self.message = "no FBG frames: advancing is blocked (strains unknown)"
            return
        tol = self.settings.position_tolerance
        goal = min(max(goal, obs.advance - step - tol), obs.advance + step + tol)  # no runaway
        note = ""
        limit = self._travel_limit()
        if sign > 0 and limit is not None and goal > limit:
            goal, note = max(limit, min(obs.advance, goal)), "travel-past-contact limit"
        lo, hi = self.drive.translation_limits
        if not lo <= goal <= hi:
            goal, note = min(max(goal, lo), hi), "translation limit"
        self.goal = JointState(self.goal.roll, goal)
        self.message = f"advance goal {goal * 1e3:.3f} mm" + (f" (at the {note})" if note else "")

    def _jog_roll(self, sign: float) -> None:
        assert self.goal is not None
        self.roll_to(self.goal.roll + sign * self.step_size[1])

    def roll_to(self, goal: float) -> None:
        """The roll goal to ``goal``: never in contact, within the limits and a step."""
        assert self.obs is not None
        assert self.goal is not None
        if self.obs.contact or self.x_contact is not None:
            self.message = "in contact: roll is blocked (retract first)"
            return
        obs, step = self.obs, self.step_size[1]
        tol = self.settings.roll_tolerance
        goal = min(max(goal, obs.roll - step - tol), obs.roll + step + tol)
        lo, hi = self.drive.roll_limits
        note = ""
        if not lo <= goal <= hi:
            goal, note = min(max(goal, lo), hi), " (at the roll limit)"
        self.goal = JointState(goal, self.goal.translation)
        self.message = f"roll goal {math.degrees(goal):.2f} deg{note}"

    def _change_tube(self, direction: int) -> Effect | None:
        assert self.obs is not None
        exposed = self.obs.advance - self.tube.flush_translation
        if exposed > self.settings.position_tolerance or self.state is State.POSITIONING:
            self.message = (
                f"retract the sensor into the tube before changing tubes "
                f"(exposed {exposed * 1e3:.2f} mm)"
            )
            return None
        self._tube_index = (self._tube_index + direction) % len(self.tubes)
        self.message = f"tube {self.tube.name} ({self.tube.tip_angle_deg:g} deg)"
        return Effect("tube", self.tube.name)

    def _rearm(self) -> Effect | None:
        if self.state is State.RETRACTING:
            self.message = "retracting: wait until it is done"
            return None
        if self.state not in (State.ABORTED, State.FAULT):
            self.message = "nothing to re-arm"
            return None
        was_fault = self.state is State.FAULT
        self.state, self.goal, self.fault, self._estop = State.IDLE, None, None, False
        self.message = "re-armed"
        return Effect("recover") if was_fault else None

    def fail(self, reason: str) -> None:
        """The front end could not do what an effect asked (e.g. re-enable torque)."""
        self.state, self.fault, self.message = State.FAULT, reason, reason

    # -- saving a target ------------------------------------------------------------------------
    def suggested_name(self) -> str:
        if self.obs is None:
            return self.tube.name
        roll = math.degrees(self.obs.roll)
        return f"{self.tube.name}-roll{roll:.0f}-t{self.obs.advance * 1e3:.1f}"

    def _begin_save(self) -> Effect | None:
        if self.obs is None or not math.isfinite(self.obs.advance):
            self.message = "no pose to save yet"
            return None
        self.prompt = ""
        self.message = f"name for this pose (enter: {self.suggested_name()}, esc: cancel)"
        return None

    def _prompt_key(self, key: str) -> Effect | None:
        assert self.prompt is not None
        if key == "escape":
            self.prompt, self.message = None, "not saved"
        elif key == "backspace":
            self.prompt = self.prompt[:-1]
        elif key == "enter":
            name = self.prompt or self.suggested_name()
            self.prompt = None
            return Effect("save", name)
        elif len(key) == 1 and NAME_CHARS.fullmatch(key) and len(self.prompt) < MAX_NAME:
            self.prompt += key
        return None

    def target(self, name: str, note: str = "") -> TargetConfig:
        """The measured pose (not the goal) as a stored target."""
        if self.obs is None:
            raise ValueError("no pose measured yet")
        return TargetConfig(
            name=name,
            tube=self.tube.name,
            roll_deg=round(math.degrees(self.obs.roll), 3),
            translation_mm=round(self.obs.advance * 1e3, 4),
            note=note,
        )

    # -- the control tick -----------------------------------------------------------------------
    def step(self, obs: Observation) -> Command:
        """One control tick: track contact and buckling, apply the guards, return the goal."""
        self.obs = obs
        self.gated = self.gated or bool(obs.gate)
        if self.goal is None:
            self.goal = JointState(obs.roll, obs.advance)
        if obs.contact:
            if self.x_contact is None:
                self.x_contact = obs.advance
                self.detector.reset()
            self.buckled = self.detector.update(obs.strains, obs.advance, obs.tip_force)
        else:
            self.x_contact, self.buckled = None, False
        self._guard(obs)
        self._hold_travel_limit()
        if self.state is State.RETRACTING:
            if abs(obs.advance - self.home) > self.settings.position_tolerance:
                return Command(self.home, obs.roll, self.fast_speed or self.drive.max_speed)
            self.state = State.ABORTED if self._estop else State.FAULT
            self.goal = JointState(obs.roll, obs.advance)
            self.message = f"retracted ({self.fault or 'emergency stop'}); r re-arms"
        if self.state is State.FAULT:
            return Command(obs.advance, obs.roll, 0.0, torque=False)
        if self.state is State.ABORTED:
            return Command(obs.advance, obs.roll, 0.0)
        g = self.goal
        moving = (
            abs(g.translation - obs.advance) > self.settings.position_tolerance
            or abs(g.roll - obs.roll) > self.settings.roll_tolerance
        )
        self.state = State.POSITIONING if moving else State.IDLE
        return Command(g.translation, g.roll, self.speed)

    def _travel_limit(self) -> float | None:
        """How far a jog may go (m): short of the travel-past-contact guard; None if free."""
        if self.x_contact is None:
            return None
        g, margin = self.guards, self.settings.travel_margin
        return self.x_contact + g.max_travel_past_contact - margin

    def _hold_travel_limit(self) -> None:
        """A jog that began before the contact stops short of the travel limit, not at it."""
        limit = self._travel_limit()
        if limit is not None and self.goal is not None and self.goal.translation > limit:
            self.goal = JointState(self.goal.roll, limit)
            self.message = f"contact: advance goal held at {limit * 1e3:.3f} mm (travel limit)"

    def _guard(self, obs: Observation) -> None:
        if self.state is State.RETRACTING:
            if obs.servo_fault is not None:
                self.fault = f"servo fault while retracting: {obs.servo_fault}"
                self.state, self.message = State.FAULT, self.fault
            return
        if self.state in (State.ABORTED, State.FAULT):
            return
        reason = None
        if obs.servo_fault is not None:
            reason = f"servo fault: {obs.servo_fault}"
        elif (violation := limit_violation(self.guards, obs, self.x_contact)) is not None:
            reason = violation
        elif self.x_contact is not None and obs.stream_age > self.guards.stream_lost:
            reason = f"FBG stream lost ({obs.stream_age * 1e3:.0f} ms without a frame)"
        if reason is not None:
            self.fault = reason
            self._go_retract(f"FAULT: {reason}")

    def _go_retract(self, why: str) -> None:
        self.state = State.RETRACTING
        self.message = f"{why}: retracting to {self.home * 1e3:.3f} mm"

    # -- what the screen shows --------------------------------------------------------------------
    def view(self) -> TeleopView:
        obs = self.obs
        roll = adv = exposed = None
        tip = tangent = sensor_tip = None
        strains: tuple[float, ...] = ()
        if obs is not None and math.isfinite(obs.roll) and math.isfinite(obs.advance):
            roll, adv = obs.roll, obs.advance
            pose = kinematics.forward(self.tube, obs.roll, obs.advance)
            exposed = pose.exposed_length
            tip, tangent, sensor_tip = (
                _triple(pose.tube_tip),
                _triple(pose.tangent),
                _triple(pose.sensor_tip),
            )
        if obs is not None:
            strains = obs.strains
        past = None
        if obs is not None and self.x_contact is not None:
            past = obs.advance - self.x_contact
        return TeleopView(
            state=self.state,
            tube=self.tube,
            roll=roll,
            advance=adv,
            goal=self.goal,
            step=self.step_size,
            speed=self.speed,
            exposed_length=exposed,
            tube_tip=tip,
            tangent=tangent,
            sensor_tip=sensor_tip,
            strains=strains,
            strain_norm=math.sqrt(sum(s * s for s in strains)),
            strain_limit=self.guards.strain_limit,
            contact=bool(obs is not None and obs.contact),
            buckled=self.buckled,
            travel_past_contact=past,
            travel_limit=self.guards.max_travel_past_contact,
            stream_age=math.inf if obs is None else obs.stream_age,
            fault=self.fault,
            message=self.message,
            prompt=self.prompt,
            tip_force=None if obs is None else obs.tip_force,
            gate=None if obs is None or not self.gated else bool(obs.gate),
        )


def _triple(v: kinematics.Vector) -> tuple[float, float, float]:
    return float(v[0]), float(v[1]), float(v[2])
