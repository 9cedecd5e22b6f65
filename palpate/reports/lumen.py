"""What ``palpate design --lumen-mm`` adds to the design's report: what passes the channel, the
moduli one sensor spans through it, the limits that bind at either end and the second sensor."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from palpate.campaigns.designcheck import UNITS
from palpate.sensor_design import DesignConstraints
from palpate.sensor_design.lumen import Lumen, Span
from palpate.sensor_design.results import CHECKS

LIMIT_NAMES = {
    "force": "force resolution",
    "resolution": "depth resolution",
    "depth": "delta/R",
    "thickness": "the layer",
    "plane": "the beam's softness (it must still buckle in the gratings' plane)",
    "detection": "buckling detection",
    "delta_bias": "travel that is not indentation",
    "fiber_strain": "the fiber's strain",
    "weight": "the beam's own weight held across",
}


@dataclass(frozen=True)
class LumenReport:
    """The lumen, the span of the range through it, the constraints and the unit shown."""

    lumen: Lumen
    span: Span
    constraints: DesignConstraints
    unit: str

    def as_dict(self) -> dict[str, Any]:
        """The ``lumen`` entry of ``palpate design --json``."""
        lumen, span, c, unit = self.lumen, self.span, self.constraints, UNITS[self.unit]
        res = c.tip_force_resolution
        return {
            "diameter_mm": lumen.diameter * 1e3,
            "clearance_mm": lumen.clearance * 1e3,
            "passage_mm": lumen.passage * 1e3,
            "largest_tip_radius_mm": lumen.largest_tip() * 1e3,
            "tip_force_resolution_mn": None if res is None else res * 1e3,
            "smallest_critical_load_mn": c.smallest_critical_load * 1e3,
            "max_depth_ratio": c.max_depth_ratio,
            "one_sensor": span.one_sensor,
            f"requested_{self.unit.lower()}": [e / unit for e in span.requested],
            f"ranges_{self.unit.lower()}": [[a / unit, b / unit] for a, b in span.ranges],
            "lowest_blocked_by": _limits(span.lowest_blocked),
            "top_blocked_by": _limits(span.top_blocked),
        }

    def text(self) -> str:
        """The lumen's paragraph of ``palpate design``'s report."""
        lumen, span, c, name = self.lumen, self.span, self.constraints, self.unit

        def shown(e: float) -> str:
            return f"{e / UNITS[name]:.3g}"

        lo, hi = span.requested
        res = c.tip_force_resolution
        head = (
            f"lumen {lumen.diameter * 1e3:g} mm (passage {lumen.passage * 1e3:.3g} mm: tip R <= "
            f"{lumen.largest_tip() * 1e3:.3g} mm), tip grating resolution "
            + ("none" if res is None else f"{res * 1e3:.3g} mN (P_cr >= "
               f"{c.smallest_critical_load * 1e3:.3g} mN)")
            + f", delta/R <= {c.max_depth_ratio:g}"
        )  # fmt: skip
        if span.one_sensor:
            return f"{head}\n  one sensor spans {shown(lo)}-{shown(hi)} {name}"
        lines = [head, f"  one sensor cannot span {shown(lo)}-{shown(hi)} {name} through it"]
        if not span.ranges:
            lines.append(
                f"  no sensor through it reaches any of the range: {_named(span.lowest_blocked)}"
            )
            return "\n".join(lines)
        if span.lowest_blocked:
            lines.append(
                f"  below {shown(span.ranges[0][0])} {name} no sensor through it works: "
                f"{_named(span.lowest_blocked)}"
            )
        first = span.ranges[0]
        lines.append(f"  the widest one sensor spans: {shown(first[0])}-{shown(first[1])} {name}")
        if span.top_blocked:
            lines.append(f"    past it: {_named(span.top_blocked)}")
        if len(span.ranges) > 1:
            second = span.ranges[1]
            lines.append(f"  a second sensor: {shown(second[0])}-{shown(second[1])} {name}")
        return "\n".join(lines)


def _limits(names: tuple[str, ...]) -> list[dict[str, str]]:
    return [{"check": n, "limit": LIMIT_NAMES.get(n, n), "description": CHECKS[n]} for n in names]


def _named(names: tuple[str, ...]) -> str:
    return ", ".join(LIMIT_NAMES.get(n, n) for n in names) or "(no check named)"
