"""Finding the surface normal by light touches, then the orthogonal pose (issue 18).

On a real sample the normal is not known in advance (DESIGN, "Orthogonal indentation"). The
robot can only turn its sensor by rolling its tube, and a roll of a bent tube also moves the
tip sideways: touching the surface at a few rolls around the plan gives points on it. This
module runs the touches tick by tick (:class:`ProbeRoutine`, a small state machine the
indentation machine steps in its PROBING state); :mod:`robot.probe_plan` holds the geometry and
the decisions (where the next touch can be, the fit, the orthogonal pose, reachability).

The touches, in order: the plan's roll (the first touch is the plan's approach), a small roll
to one side, the full roll on that side, the full roll on the other (``offsets``). Moving
between touches is the dangerous part (a roll sweeps the tip sideways, toward where a tilted
surface may be higher): the stage keeps behind where the surface can be on the rays the roll
is about to sweep, and an FBG interlock holds the roll whenever the beam shows a load or a bow,
whatever the surface model says. A touch that never comes within the window where the surface
must be, or a pattern that outlasts its budget (``ProbeSettings.budget``, from the drive's
limits), is a geometric answer: the trial ends ``unreachable`` with the reason (torque on), never
on a state timeout; a straight tube (one line at every roll) touches once and cannot tell the
normal. The result (:class:`ProbeResult`) carries the measured normal, its 1-sigma angle, the
residual angle (the trial's misalignment) and the miss.
"""

from __future__ import annotations

import dataclasses
import enum
import math

import numpy as np

from ..estimation.pose.surface import load_crossing
from .indentation import REZERO_SETTLE_TICKS, Command, Observation, TrialPlan
from .probe_plan import ProbeGeometry, ProbeSettings
from .probe_result import ProbeResult, Touch

MOVE_LOOKAHEAD = math.radians(12.0)  # roll ahead of the present the stage keeps clear of
NEAR = 0.03  # rad of roll ahead the stage must be clear of before the roll moves on
ON_RAY = math.radians(2.0)  # within this roll of a touch the tip still faces its dimple
TOUCH_TOP = 2.0  # a seek goes on to this many thresholds, for the fit of its ramp
TOUCH_FREE = 0.5  # the tip is free again below this share of the threshold
FREE_TICKS = 3  # ticks running the FBG must show a free tip
BASELINE_TICKS = 16  # free ticks at the start of a seek that give its axial strain's zero
TOUCH_BOW = 10.0  # a bow this many thresholds deep ends a touch early (an imperfect beam)

__all__ = [
    "ProbeGeometry",
    "ProbeResult",
    "ProbeRoutine",
    "ProbeSettings",
    "Touch",
    "probe_budget",
]

BUDGET_SLACK = 2e-3  # m: a seek's allowance for where the surface can be, beyond its window
BUDGET_MARGIN = 1.5  # the budget over the nominal pattern's time


def probe_budget(
    offsets: tuple[float, ...],
    approach_window: float,
    speed: float,
    fast_speed: float,
    roll_speed: float,
    settle: float,
    search: float = 0.0,
) -> float:
    """Seconds a probing pattern needs at most on this drive, times ``BUDGET_MARGIN``: each
    touch a seek over the approach window, the clearance and ``BUDGET_SLACK`` at the probe
    ``speed`` and the lift back at ``fast_speed``, the settle (s) for its strain zero; the first
    touch's ``search`` (m) past its window; the rolls of the pattern there and back at
    ``roll_speed`` (rad/s) and a whole turn for the way out. A pattern that has not found the
    surface by then will not: the answer is geometric (``unreachable``), before any state
    timeout."""
    seek = approach_window + ProbeSettings.clearance + BUDGET_SLACK
    touches = 1 + len(offsets)
    per_touch = seek / speed + seek / fast_speed + settle
    first = search / speed  # the first touch's look past the window
    rolls = 2.0 * sum(abs(o) for o in offsets) + math.tau
    return BUDGET_MARGIN * (first + touches * per_touch + rolls / roll_speed)


class _Phase(enum.Enum):
    SEEK = "seek"
    LIFT = "lift"
    MOVE = "move"
    SETTLE = "settle"
    LEAVE = "leave"


class ProbeRoutine:
    """The probing step of one trial, a small state machine of its own: hand it each tick's
    :class:`Observation`; it returns the :class:`Command` to send, or, once done, the
    :class:`ProbeResult` (a ``str`` instead when it found no surface where one must be, or ran
    out of its budget: the machine ends the trial ``unreachable`` with it).

    A touch: SEEK at the probe speed until the FBG's axial strain (the bow along the onset
    shape at the present exposed length taken out, zeroed on the seek's first ticks) reaches
    twice the threshold; the touch is where the Hertz power fitted to the seek's ramp crosses
    the threshold (with 3 gratings the axial strain has ~5 ue of noise, ~45 um of stage travel
    on a 300 kPa sample for one tick; the fit brings it to ~10 um); LIFT: plan the next touch
    and MOVE to its roll while retracting behind the surface on every ray the roll sweeps (the
    roll waits until the tip is free and wherever the retract has not caught up); SETTLE at
    rest and take the strain zero again (the beam's own weight bends it differently at
    another roll); SEEK again."""

    def __init__(self, geometry: ProbeGeometry, settings: ProbeSettings, plan: TrialPlan) -> None:
        self.geometry = geometry
        self.settings = settings
        self.plan = plan
        self.rolls = geometry.probe_rolls(plan.roll, settings.offsets)
        self.touches: list[Touch] = []
        self.phase = _Phase.SEEK
        upper = geometry.translation_limits[1]  # the first touch also looks past the window
        self.limit = min(plan.contact_advance + plan.approach_window + settings.search, upper)
        self.goal = math.nan
        self.result: ProbeResult | None = None
        self._sweep: tuple[list[float], list[float]] = ([], [])  # rolls, safe advance on each
        self._ticks = 0
        self._free = True  # the tip is off the surface
        self._free_ticks = FREE_TICKS
        self._loaded_ticks = 0
        self._zero_roll = plan.roll  # the roll the strains were last zeroed at
        self._ramp: list[tuple[float, float]] = []  # (advance, axial strain) of this seek
        self._ramp_strains: list[tuple[float, ...]] = []  # the strains of those ticks
        self._started: float | None = None  # time of the first tick

    @property
    def roll(self) -> float:
        """The roll of the touch under way (the last one once all are made)."""
        return self.rolls[min(len(self.touches), len(self.rolls) - 1)]

    def step(self, obs: Observation) -> Command | ProbeResult | str:
        if self._started is None:
            self._started = obs.t
        spent = obs.t - self._started
        if spent > self.settings.budget and self.phase is not _Phase.LEAVE:
            return (
                f"probing: the surface was not found within the budget of "
                f"{self.settings.budget:.1f} s (the drive's limits), {len(self.touches)} of "
                f"{len(self.rolls)} touches made"
            )
        handler = {
            _Phase.SEEK: self._seek,
            _Phase.LIFT: self._lift,
            _Phase.MOVE: self._move,
            _Phase.SETTLE: self._settle,
            _Phase.LEAVE: self._leave,
        }[self.phase]
        return handler(obs)

    @property
    def _threshold(self) -> float:
        """The load that is a touch: ``touch_force`` (N) with a tip grating, else
        ``touch_strain``."""
        s = self.settings
        return s.touch_strain if s.touch_force is None else s.touch_force

    def _load(self, obs: Observation) -> float:
        """The tick's load in the threshold's unit: the tip grating's (N) when the settings
        read it, else the axial strain; NaN when the tick has none."""
        if self.settings.touch_force is not None:
            return math.nan if obs.tip_force is None else obs.tip_force
        return self.geometry.axial(obs.strains, obs.advance)

    def _seek(self, obs: Observation) -> Command | ProbeResult | str:
        s, threshold = self.settings, self._threshold
        axial = self._load(obs)
        if math.isfinite(axial):
            self._ramp.append((obs.advance, axial))
            self._ramp_strains.append(obs.strains)
        load = axial - self._baseline()
        bowed = max((abs(e) for e in obs.strains), default=0.0) >= TOUCH_BOW * s.touch_strain
        if math.isfinite(load) and (load >= TOUCH_TOP * threshold or bowed):
            # a bow without the load is a slipping tip (the surface too steep for its friction)
            slipped = bowed and load < threshold
            start, x = (obs.advance, obs.advance) if slipped else self._crossing()
            touch = self.geometry.touch(obs.roll, x)
            self.touches.append(dataclasses.replace(touch, slipped=slipped, depth=x - start))
            self._ramp, self._ramp_strains = [], []
            self.phase = _Phase.LIFT
            return self._lift(obs)
        if obs.advance >= self.limit - self.plan.position_tolerance:
            return (
                f"probing: no surface within {self.limit * 1e3:.2f} mm of stage travel at roll "
                f"{math.degrees(self.roll):.1f} deg"
            )
        return Command(self.limit, self.roll, self._seek_speed())

    def _seek_speed(self) -> float:
        """The first touch's speed, then as fast as the stage stops (v^2 / 2a) within half the
        depth the touches went to (a soft sample yields more, so it can be met faster)."""
        s = self.settings
        depths = [t.depth for t in self.touches if not t.slipped and t.depth > 0]
        if not depths or not math.isfinite(s.decel):
            return s.speed
        reach = TOUCH_TOP ** (2.0 / 3.0) * min(depths)  # a touch's depth at its top load
        return min(max(math.sqrt(s.decel * reach), s.speed), s.fast_speed)

    def _baseline(self) -> float:
        """The load of the free beam on this seek, in the threshold's unit: the mean of its
        first ticks (the seek starts ``clearance`` or more before the surface), 0 until there
        are enough."""
        if len(self._ramp) < BASELINE_TICKS // 2:
            return 0.0
        return float(np.mean([a for _, a in self._ramp[:BASELINE_TICKS]]))

    def _crossing(self) -> tuple[float, float]:
        """Where the seek's load began and where it reached the threshold: the Hertz power
        fitted to the whole seek (``estimation.pose.surface.load_crossing``), on the loads of the
        full beam state when the geometry has them; the last tick's advance (twice) when the
        fit fails."""
        xs = [x for x, _ in self._ramp]
        ys = [a for _, a in self._ramp]
        loads = self.geometry.loads
        if self.settings.touch_force is None and loads is not None and len(xs) >= 4:
            ys = loads(np.array(xs), np.array(self._ramp_strains)).tolist()
        found = load_crossing(xs, ys, self._threshold) if len(xs) >= 4 else None
        last = self._ramp[-1][0]
        return (last, last) if found is None else found

    def _lift(self, obs: Observation) -> Command | ProbeResult:
        """Plan what follows a touch (the next move, or the re-plan and the way out) and start
        backing off; nothing rolls until the tip is free (``_freed``)."""
        s, geo = self.settings, self.geometry
        self._free, self._free_ticks, self._loaded_ticks = False, 0, 0
        self.goal = self.touches[-1].advance - s.clearance
        if len(self.touches) == len(self.rolls):
            self.result = geo.replan(self.touches, self.plan, s)  # roll: the way out's turn
            self._plan_sweep(obs.roll, self.result.roll)
            self.phase = _Phase.LEAVE
            return self._leave(obs)
        if len(self.touches) == 2:
            self.rolls = _near_side_last(self.rolls, self.touches)
        roll = self.rolls[len(self.touches)]
        x, slack = geo.predict(self.touches, roll, s)
        self._plan_sweep(obs.roll, roll)
        self.limit = x + slack + s.clearance + self.plan.approach_window
        self.phase = _Phase.MOVE
        return self._move(obs)

    def _plan_sweep(self, start: float, end: float) -> None:
        """The advance behind the surface on the rays from roll ``start`` to ``end``."""
        rolls, safe = self.geometry.sweep_needs(self.touches, start, end, self.settings)
        self._sweep = (rolls, safe) if rolls[0] <= rolls[-1] else (rolls[::-1], safe[::-1])

    def _freed(self, obs: Observation) -> bool:
        """Whether the tip is off the surface, by the FBG: ``FREE_TICKS`` ticks running with
        neither load (half the touch's) nor a bow make it free, two with either make it touch
        again (the noise of one tick does neither). Whenever it comes free the stage keeps
        ``clearance`` behind; while it is not, nothing rolls, whatever the surface model says.
        The load counts only near the roll the strains were zeroed at: the beam's own weight
        bends it differently at another roll (tens of microstrain), the bow counts always."""
        th = self.settings.touch_strain
        bow = max((abs(e) for e in obs.strains), default=0.0)
        loaded = bow >= TOUCH_BOW * th
        if abs(obs.roll - self._zero_roll) < ON_RAY:  # rolled away, the weight moves the zero
            loaded = loaded or self._load(obs) > TOUCH_FREE * self._threshold
        self._free_ticks = 0 if loaded else self._free_ticks + 1
        self._loaded_ticks = self._loaded_ticks + 1 if loaded else 0
        if self._free and self._loaded_ticks >= 2:
            self._free = False
        elif not self._free and self._free_ticks >= FREE_TICKS:
            self._free = True
            self.goal = min(self.goal, obs.advance - self.settings.clearance)
        return self._free

    def _safe(self, start: float, end: float) -> float:
        """The advance behind the surface on every ray from roll ``start`` to ``end``."""
        rolls, safe = self._sweep
        lo, hi = min(start, end), max(start, end)
        inside = [a for r, a in zip(rolls, safe, strict=True) if lo < r < hi]
        ends = np.interp([lo, hi], rolls, safe)
        return float(min(*ends, *inside)) if inside else float(min(ends))

    def _move(self, obs: Observation) -> Command:
        """Roll to the next touch (``_travel``), then settle there."""
        cmd, arrived = self._travel(obs, self.roll, (NEAR, MOVE_LOOKAHEAD), math.inf)
        if arrived:
            self.phase, self._ticks = _Phase.SETTLE, 0
        return cmd

    def _travel(
        self, obs: Observation, roll: float, spans: tuple[float, float], cap: float
    ) -> tuple[Command, bool]:
        """Roll to ``roll``, the stage following the surface on the rays the roll is about to
        sweep (``spans[1]`` ahead) and never beyond ``cap``: retract and roll at once; the
        roll holds while the tip is on the surface or the stage is not yet behind it on the
        next ``spans[0]`` of roll. Whether the stage is there, at rest."""
        s = self.settings
        if not self._freed(obs):  # back off along the ray until the FBG says the tip is free
            self.goal = min(self.goal, obs.advance - s.clearance)
            return Command(self.goal, obs.roll, s.fast_speed), False
        togo = roll - obs.roll
        near = self._safe(obs.roll, obs.roll + math.copysign(min(abs(togo), spans[0]), togo))
        ahead = self._safe(obs.roll, obs.roll + math.copysign(min(abs(togo), spans[1]), togo))
        on_last_ray = abs(obs.roll - self.touches[-1].roll) < ON_RAY
        goal = min(min(self.goal, ahead) if on_last_ray else ahead, cap)
        at_roll = abs(togo) <= self.plan.roll_tolerance
        if at_roll and abs(obs.advance - goal) <= self.plan.position_tolerance:
            self.goal = goal
            return Command(goal, roll, 0.0), True
        safe = obs.advance <= near + self.plan.position_tolerance
        return Command(goal, roll if safe else obs.roll, s.fast_speed), False

    def _settle(self, obs: Observation) -> Command:
        self._ticks += 1
        if self._ticks <= REZERO_SETTLE_TICKS:
            return Command(self.goal, self.roll, 0.0)
        self.phase = _Phase.SEEK
        self._zero_roll = obs.roll
        return Command(self.goal, self.roll, 0.0, rezero=True)

    def _leave(self, obs: Observation) -> Command | ProbeResult:
        """Roll to the chosen pose (``_travel``), the stage going back behind the surface on
        every ray still to sweep and behind the pose's stand-off (it goes there anyway) as the
        roll moves on; the trial's positioning takes it to its stand-off from there."""
        assert self.result is not None
        r = self.result
        cmd, arrived = self._travel(obs, r.roll, (NEAR, math.inf), r.retract_to)
        if arrived:
            return dataclasses.replace(self.result, retract_to=self.goal)
        return cmd


def _near_side_last(rolls: list[float], touches: list[Touch]) -> list[float]:
    """The touches' rolls with the full steps ordered so the last lies on the side where the
    first two touches found the surface nearer: along a roll a plane is nearest where the ray
    meets it square, so the orthogonal pose lies on that side and the way out is short (the
    same rolls, only the order of the third and fourth)."""
    if len(rolls) < 4:
        return rolls
    (a, b), nearer = rolls[2:4], touches[1].advance < touches[0].advance
    toward = math.copysign(1.0, rolls[1] - rolls[0]) * (1.0 if nearer else -1.0)
    if (b - a) * toward < 0:
        a, b = b, a
    return [*rolls[:2], a, b, *rolls[4:]]
