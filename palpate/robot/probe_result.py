"""What probing touched and found: the touches and the result the state machine acts on.

Plain records with no behaviour beyond their dictionaries, below both the state machine
(``robot.indentation``, which holds a trial's ``ProbeResult``) and the probing step
(``robot.probe_plan``, ``robot.probing``, which make them), so neither imports the other for
them.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Touch:
    """One light touch: the roll and stage advance (rad, m) and the tip centre and the sensor
    axis there (3-tuples, base frame); ``slipped`` when the FBG saw the beam bow without the
    load rising (the tip slid on a surface too steep for its friction): kept for the moves,
    left out of the fit; ``depth``: how far past the surface the touch is (its load's onset
    to its threshold), which a move must keep clear of besides the surface's own doubt."""

    roll: float
    advance: float
    centre: tuple[float, float, float]
    tangent: tuple[float, float, float]
    slipped: bool = False  # the tip slid instead of loading: not a point of the surface
    depth: float = 0.0  # m of advance from where the load began to the touch


@dataclass(frozen=True)
class ProbeResult:
    """What probing found and the pose it chose.

    ``reachable`` False means no pose of the trial's tube meets the surface within the
    tolerances (``reason`` says which); ``roll`` and ``contact_advance`` are then the plan's.
    ``misalignment`` (rad) is the residual angle of the chosen pose to the measured normal,
    ``normal_sigma`` (rad) the normal's 1-sigma angle (nan when it was not measured), ``miss``
    (m) the distance from the first touch's surface point to the chosen contact."""

    reachable: bool
    reason: str
    roll: float
    contact_advance: float
    misalignment: float
    normal_sigma: float
    miss: float
    normal: tuple[float, float, float] | None
    model: str
    radius: float | None
    touches: tuple[Touch, ...]
    retract_to: float

    def as_dict(self) -> dict[str, Any]:
        """Everything, for the trial log's ``probe`` record."""
        d = dataclasses.asdict(self)
        d["misalignment_deg"] = math.degrees(self.misalignment)
        d["normal_sigma_deg"] = math.degrees(self.normal_sigma)
        return d

    def summary(self) -> dict[str, Any]:
        """What was measured and decided, for a campaign's JSON (the log has the touches)."""
        return {
            "reachable": self.reachable,
            "reason": self.reason,
            "normal": self.normal,
            "normal_sigma_deg": math.degrees(self.normal_sigma),
            "model": self.model,
            "radius_mm": None if self.radius is None else self.radius * 1e3,
            "miss_mm": self.miss * 1e3,
            "roll_deg": math.degrees(self.roll),
            "touches": len(self.touches),
        }
