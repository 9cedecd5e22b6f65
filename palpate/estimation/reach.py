"""What a sensor can reach: the stage travel past contact a tissue needs to buckle it, and, for
a trial whose travel window ran out before it buckled, the modulus the tissue is below.

A trial on tissue too soft for its sensor ends when the window is used up (``robot.indentation``:
an answer, not a fault). The tip then pushed back less than P_cr at the end of the window, where
the tissue was indented at least the window less the rig's largest compliance times P_cr (the
compliance took the rest; the beam's shortening before buckling is microns). A sphere on a
half-space pushes back least at a given depth (a layer over a base pushes back more), so Hertz
at that least depth bounds the modulus from above. The bound is the belief's: a rig softer than
its largest believed compliance (a compliant tube tip nobody calibrated) takes more of the
window, and the reason says so (``unless the rig gives more than ... mm/N``, or ``the rig taken
rigid``)::

    bound = modulus_below(Reach(window=2.5e-3, p_cr=1.35, poisson=0.45, compliance=0.0), 1.75e-3)
    too_soft(fit, reason, reach, tip_radius)   # the verdict's reason, or None
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .belief import Hypothesis
from .jointfit import JointFit

NO_BUCKLING = "no buckling"  # the state machine's reason when the travel window ran out
DESIGN_HINT = "see `palpate design`"


@dataclass(frozen=True)
class Reach:
    """The trial's reach (SI): the travel past contact it may indent (None: unknown), the
    beam's P_cr at the contact's exposed length (None: unknown), the believed Poisson ratio
    and the largest compliance of the rig (m/N) it may have (None: unknown)."""

    window: float | None
    p_cr: float | None
    poisson: float | None = None
    compliance: float | None = None


def modulus_below(reach: Reach, tip_radius: float) -> float | None:
    """The modulus (Pa) a tissue that did not buckle the sensor within the window is below
    (module docstring); None without the window, P_cr, nu or the compliance, or where the
    compliance alone could take the whole window.

    >>> round(modulus_below(Reach(2.5e-3, 1.35, 0.45, 0.0), 1.75e-3) / 1e3)
    154
    """
    r = reach
    if r.window is None or not r.p_cr or r.poisson is None or r.compliance is None:
        return None
    depth = r.window - r.compliance * r.p_cr
    if depth <= 0.0:
        return None
    return float(0.75 * r.p_cr * (1.0 - r.poisson**2) / (math.sqrt(tip_radius) * depth**1.5))


def too_soft(fit: JointFit | None, reason: str, reach: Reach, tip_radius: float) -> str | None:
    """The verdict's reason when the tissue is too soft for the sensor (the trial ended with its
    window used up, or its fit needs more travel than the window to buckle), else None."""
    if reach.window is None:
        return None
    mm = reach.window * 1e3
    bound = modulus_below(reach, tip_radius) if reason.startswith(NO_BUCKLING) else None
    below = (
        "" if bound is None else f"; the tissue is below {bound / 1e3:.3g} kPa" + _assumed(reach)
    )
    if reason.startswith(NO_BUCKLING) and (fit is None or not fit.success):
        return (
            f"tissue too soft for this sensor: no buckling within the {mm:g} mm travel window"
            f"{below}; {DESIGN_HINT}"
        )
    needed = depth_to_buckle(fit, reach.p_cr, tip_radius)
    if needed is None or needed <= reach.window or fit is None or fit.modulus is None:
        return None
    return (
        f"tissue too soft for this sensor: buckling needs more than the {mm:g} mm travel window "
        f"({needed * 1e3:.1f} mm at {fit.modulus / 1e3:.0f} kPa){below}; {DESIGN_HINT}"
    )


def _assumed(reach: Reach) -> str:
    """The compliance a bound assumes, said."""
    if not reach.compliance:
        return " (the rig taken rigid)"
    return f" unless the rig gives more than {reach.compliance * 1e3:.2g} mm/N"


def depth_to_buckle(fit: JointFit | None, p_cr: float | None, tip_radius: float) -> float | None:
    """Stage travel past contact (m) at which the fitted tissue pushes back P_cr: the
    indentation there plus the rig's compliance times P_cr (None without a fit or P_cr)."""
    if fit is None or not fit.success or fit.modulus is None or fit.best is None or not p_cr:
        return None
    best = Hypothesis.described(fit.best, tip_radius)
    depth = np.geomspace(1e-7, 0.02, 600)
    force = np.maximum.accumulate(best.law.force(fit.modulus, depth))
    k = int(np.searchsorted(force, p_cr))
    if k >= depth.size:
        return math.inf
    return float(depth[k]) + best.compliance * p_cr
