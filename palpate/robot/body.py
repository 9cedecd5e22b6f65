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

Usage::

    body = BodyWatch()
    body.see(obs)                       # every tick
    body.hold_began(obs, plan.gate_fresh), body.approach(plan, advance), body.indent_speed(plan)
"""

from __future__ import annotations

from dataclasses import dataclass

from .guards import Observation
from .plan import TrialPlan

STANDOFF_HINT = (  # a contact while waiting at the stand-off: the tissue came to the tip
    ": the tissue's motion (the breath, the heart) reached the waiting tip; raise "
    "campaign.standoff_mm past the breath's excursion"
)


@dataclass
class BodyWatch:
    """The gate and the heart as the ticks have shown them so far."""

    failed_holds: int = 0  # breath holds that ended before the trial did
    beating: bool = False  # an R wave was seen this trial
    _open: bool = True  # the gate last seen
    _rose: float | None = None  # when it last rose (s)

    def see(self, obs: Observation) -> None:
        """Take one tick's gate and ECG pulse."""
        if obs.gate is not None:
            if obs.gate and not self._open:
                self._rose = obs.t
            self._open = obs.gate
        self.beating = self.beating or obs.beat

    def hold_began(self, obs: Observation, fresh: float) -> bool:
        """A breath hold is on at ``obs`` and began at most ``fresh`` s before."""
        return bool(obs.gate) and self._rose is not None and obs.t - self._rose <= fresh

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
