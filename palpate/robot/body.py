"""What the indentation machine (``robot.indentation``) watches of the body's motion: the
ventilator's breath-hold gate (frame status bit 6) and an ECG monitor's R waves (bit 7).

- A breath hold is taken only as it begins (its gate rose at most ``TrialPlan.gate_fresh``
  before: a hold already under way has an end nobody knows); a hold that ends before the trial
  does is counted (:attr:`BodyWatch.failed_holds`), and the machine retracts and waits for the
  next one, up to ``TrialPlan.hold_retries`` times.
- Once the heart has been seen to beat, the tip indents at ``TrialPlan.heart_speed`` at most
  (0.1 mm/s: the 0.2-0.6 mm to buckling then span 2-7 beats), so the estimate can tell the beat
  from the tissue (``estimation.trial.motion``). The time this takes is made in the approach:
  through the stand-off at full speed to ``TrialPlan.heart_margin`` before the expected
  surface. Only in a breath hold (``TrialPlan.gated``): free breathing moves the tissue more
  than the beat, and no faster. Without an ECG nothing changes.
- Until the tip has touched the tissue in ``TrialPlan.heart_touches`` of the heart's quiet
  phases (``TrialPlan.heart_quiet`` of the R-R interval after an R wave: mid-diastole, cardiac
  CT's quiet window), the buckling detector reads only the quiet phase's ticks
  (:meth:`BodyWatch.reads`). Beside a strong beat and a stiff sample the systole alone buckles
  the beam within a beat or two of the first touch, before the stage has pressed the still
  tissue at all; the beam springs back in diastole, so the machine goes on until it buckles
  with the heart at rest, and the record holds the quiet windows the estimate needs. A soft
  sample's record has them long before the systole buckles the beam: it ends there, as before.
  At buckling the stage stands (no post-buckling travel, :meth:`BodyWatch.post_travel`) through
  ``TrialPlan.heart_windows`` more quiet windows before it retracts (:meth:`BodyWatch.settled`):
  the beam at its buckling load, the stage still, only the breath hold's drift moves the load
  in those windows, and the estimate reads the drift there (``estimation.trial.strobe``).

Usage::

    body = BodyWatch()
    body.see(obs)                       # every tick
    body.hold_began(obs, plan.gate_fresh), body.approach(plan, advance), body.indent_speed(plan)
    body.reads(obs, plan)               # feed the buckling detector only then
    body.mark(); body.settled(obs.t, plan)  # at contact and buckling; after: may it retract?
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .guards import Observation
from .plan import TrialPlan

STANDOFF_HINT = (  # a contact while waiting at the stand-off: the tissue came to the tip
    ": the tissue's motion (the breath, the heart) reached the waiting tip; raise "
    "campaign.standoff_mm past the breath's excursion"
)


R_WAVES_KEPT = 5  # the R-R interval is the median of the last four
R_WAVES_LOST = 2.5  # R-R intervals without an R wave: the ECG is lost, every tick is quiet


@dataclass
class BodyWatch:
    """The gate and the heart as the ticks have shown them so far."""

    failed_holds: int = 0  # breath holds that ended before the trial did
    beating: bool = False  # an R wave was seen this trial
    _open: bool = True  # the gate last seen
    _rose: float | None = None  # when it last rose (s)
    _pulse: bool = False  # the ECG's pulse on the last tick
    _r_waves: list[float] = field(default_factory=list)  # the last R waves' times (s)
    _windows: int = 0  # quiet windows ended since the mark
    _touched: set[int] = field(default_factory=set)  # R waves whose quiet window had a contact
    _count: int = 0  # R waves seen
    _was_quiet: bool = False

    def see(self, obs: Observation) -> None:
        """Take one tick's gate and ECG pulse."""
        if obs.gate is not None:
            if obs.gate and not self._open:
                self._rose = obs.t
            self._open = obs.gate
        if obs.beat and not self._pulse:
            self._r_waves = [*self._r_waves[-(R_WAVES_KEPT - 1) :], obs.t]
            self._count += 1
        self._pulse = obs.beat
        self.beating = self.beating or obs.beat

    def period(self) -> float | None:
        """The R-R interval (s): the median of the last ones seen; None before two R waves."""
        gaps = sorted(b - a for a, b in zip(self._r_waves, self._r_waves[1:], strict=False))
        return gaps[len(gaps) // 2] if gaps else None

    def quiet(self, t: float, plan: TrialPlan) -> bool:
        """The heart is in its quiet phase at ``t``, or does not matter: no ECG, not gated, or R
        waves that stopped (none for ``R_WAVES_LOST`` intervals). False while beating and the
        R-R interval is not yet known."""
        if not (plan.gated and self.beating):
            return True
        period = self.period()
        if period is None:
            return False
        phase = (t - self._r_waves[-1]) / period
        start, end = plan.heart_quiet
        return phase > R_WAVES_LOST or start <= phase <= end

    def hold_began(self, obs: Observation, fresh: float) -> bool:
        """A breath hold is on at ``obs`` and began at most ``fresh`` s before."""
        return bool(obs.gate) and self._rose is not None and obs.t - self._rose <= fresh

    def reads(self, obs: Observation, plan: TrialPlan) -> bool:
        """Whether the buckling detector reads this indenting tick: in the heart's quiet phase,
        or every tick once ``TrialPlan.heart_touches`` quiet windows have had the tip in contact
        (a soft sample: the beam's record spans the beats before the systole buckles it), or
        where the heart does not matter (as :meth:`quiet`)."""
        quiet = self.quiet(obs.t, plan)
        if quiet and obs.contact and plan.gated and self.beating:
            self._touched.add(self._count)
        return quiet or len(self._touched) >= plan.heart_touches

    def mark(self) -> None:
        """Count the quiet windows from now (:meth:`reads`, :meth:`settled`)."""
        self._windows, self._was_quiet = 0, False
        self._touched.clear()

    def settled(self, t: float, plan: TrialPlan) -> bool:
        """``TrialPlan.heart_windows`` quiet windows have ended since the mark (call every tick
        from it), or the heart does not matter (as :meth:`quiet`)."""
        now = self.quiet(t, plan)
        self._windows += int(self._was_quiet and not now)
        self._was_quiet = now
        return not (plan.gated and self.beating) or self._windows >= plan.heart_windows

    def post_travel(self, plan: TrialPlan) -> float:
        """The travel past buckling (m): none beside a beating heart, where the stage stands
        still through the quiet windows instead (:meth:`settled`)."""
        return 0.0 if plan.gated and self.beating else plan.post_buckling_travel

    def approach(self, plan: TrialPlan, advance: float) -> tuple[float, float] | None:
        """The approach's goal and speed (m, m/s) while the heart is seen and the tip is short of
        ``heart_margin`` before the expected surface; None: the plan's approach."""
        near = plan.contact_advance - plan.heart_margin
        if plan.gated and self.beating and advance < near - plan.position_tolerance:
            return near, plan.fast_speed
        return None

    def indent_speed(self, plan: TrialPlan) -> float:
        """The plan's indentation speed, or the heart's once the heart is seen to beat (in a breath
        hold: breathing is no drift the estimate can take out beside the beat)."""
        if plan.gated and self.beating:
            return min(plan.indent_speed, plan.heart_speed)
        return plan.indent_speed
