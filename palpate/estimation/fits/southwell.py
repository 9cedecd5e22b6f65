"""The sensor beam's initial bow, fitted from its pre-buckling record (Southwell 1932).

A real sensor is not straight: with an initial bow of amplitude w0 in the first mode, linear
theory amplifies the bow under an axial load P to ``w0 / (1 - P/P_cr)``, so the bending the
gratings see (zeroed at rest, i.e. the change a = w - w0) is::

    a = w0 (P/P_cr) / (1 - P/P_cr)      <=>      a / P = a / P_cr + w0 / P_cr

Southwell's plot: a/P against a is a line with slope 1/P_cr and intercept w0/P_cr. Both come
from the record alone: the load P and the bending amplitude from the strains at every tick
(``estimation.beam.states``: a = L |z| / sqrt(c), c = MODE_SHORTENING, since the bending part of
the end shortening is c a^2 / L), on the rising part of the record between LOAD_WINDOW of the
beam model's P_cr (below, a/P is noise over a small load; above, the onset's non-linearity).
So the imperfection is measured on every trial, not configured; P_cr measured this way also
checks the beam model (a clamp or a section not as configured shows as a different P_cr).

The estimate itself needs no w0: the load and the shortening are read from the strains with the
bow's growth taken as it comes (``estimation.beam.states``). The fit is a diagnostic, logged per
trial and checked by the verdict (``estimation.verdict``).

Pure function, SI units; failure is a result with ``success`` False and a message.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..beam.elastica.constants import MODE_SHORTENING

LOAD_WINDOW = (0.3, 0.9)
MIN_POINTS = 10


@dataclass(frozen=True)
class SouthwellFit:
    """Result of :func:`southwell`: the bow w0/L and P_cr (N), or why not."""

    success: bool
    message: str
    w0_over_l: float | None = None
    critical_load: float | None = None
    n_points: int = 0

    def as_dict(self) -> dict[str, object]:
        return {
            "success": self.success,
            "message": self.message,
            "w0_over_l": self.w0_over_l,
            "critical_load": self.critical_load,
            "n_points": self.n_points,
        }


def southwell(
    load: ArrayLike, amplitude: ArrayLike, length: float, critical_load: float
) -> SouthwellFit:
    """The Southwell fit of a record.

    Args:
        load: (N,) axial loads P (N) in record order.
        amplitude: (N,) signed bending amplitudes z = sqrt(e_g/L) (``BeamStates.z``).
        length: exposed length L (m) (at the rising part of the record).
        critical_load: the beam model's P_cr (N), for the load window.

    Raises:
        ValueError: mismatched or non-finite arrays, non-positive length or P_cr.
    """
    P = np.asarray(load, dtype=np.float64)
    z = np.asarray(amplitude, dtype=np.float64)
    if P.shape != z.shape or P.ndim != 1 or not np.all(np.isfinite(P) & np.isfinite(z)):
        raise ValueError("load and amplitude must be finite (N,) arrays of one shape")
    if not (length > 0 and critical_load > 0):
        raise ValueError("length and critical_load must be > 0")
    if P.size == 0:
        return SouthwellFit(False, "no samples")
    rising = np.arange(P.size) <= int(np.argmax(P))
    lo, hi = LOAD_WINDOW
    sel = rising & (lo * critical_load < P) & (hi * critical_load > P)
    n = int(np.count_nonzero(sel))
    if n < MIN_POINTS:
        return SouthwellFit(
            False,
            f"too few pre-buckling samples: {n} between {lo:g} and {hi:g} P_cr, needs {MIN_POINTS}",
            n_points=n,
        )
    a = length * np.abs(z[sel]) / math.sqrt(MODE_SHORTENING)
    slope, intercept = np.polyfit(a, a / P[sel], 1)
    if not slope > 0:
        return SouthwellFit(False, "Southwell plot has no positive slope", n_points=n)
    return SouthwellFit(True, "ok", float(intercept / slope / length), float(1.0 / slope), n)
