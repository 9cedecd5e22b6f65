"""Gravity on the sensor beam: the sag of the free beam and the pre-bend it leaves once pinned.

What weighs: the printed tip sphere (``SensorConfig.tip_mass_g``, ~0.2 g) and the beam itself
(``linear_mass_g_per_m``, ~0.9 g/m: four NiTi wires and the fiber). Against the beam's load scale
these are small along the axis: the axial share of 2.4 mN is at most 0.2 % of the 1.35 N
buckling load at L = 42 mm, so the tissue force the estimator reads is off by that much at most,
and the world does not model it. Across the axis they are not small: the free beam sags like a
cantilever under its tip weight (W L^3 / 3 EI = 0.44 mm at L = 42 mm), ~30-70 ue at the gratings.

* Before contact the sag is a constant strain at each grating (its bending moment at a distance
  d from the tip is ``W d + q d^2 / 2`` whatever the exposed length): it is in the strain zero
  the rig takes at rest, and comes back only when a roll turns the weight in the fiber's plane.
* At contact the tip is pinned where it sagged to: the clamped-pinned beam now has its pin off
  the clamp's axis by ``w = W_eq L^3 / 3 EI`` (``W_eq = W + 3 q L / 8`` matches the tip
  deflection of the distributed weight). Compressed, that offset is amplified like an
  imperfection: linear beam-column theory gives the curvature
  ``w k^2 sin(k d) / (sin kL - kL cos kL)``, which diverges at the clamped-pinned onset
  (tan kL = kL) as the first mode does. It enters the world as the first-mode imperfection with
  the same divergence, ``w0 = OFFSET_TO_MODE * w`` (:func:`offset_to_mode`, -0.139: the offset
  and the mode bend the gratings oppositely), added to the scene's own imperfection.

Only the weight's component in the fiber's bending plane counts (the section's stiff axis takes
the rest unseen): with a downward roll the weight is in that plane, sideways across it, upward
in it again with the other sign, which is how the three orientations come to differ.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..estimation.beam.elastica.constants import P_CRIT

Vector = NDArray[np.float64]
STANDARD_GRAVITY = 9.80665  # m/s^2
GRAVITY = np.array([0.0, 0.0, -STANDARD_GRAVITY])  # base frame B: z up


@functools.lru_cache(maxsize=1)
def offset_to_mode() -> float:
    """First-mode imperfection amplitude per unit pin offset, matched where both diverge.

    Near the onset kL -> mu (tan mu = mu, mu^2 = P_CRIT) the offset's curvature tends to
    ``2 w sin(mu d/L) / (L^2 |sin mu| (1 - P/P_cr))`` and the amplified mode's to
    ``w0 (mu/L)^2 (mu sin mu + cos mu) sin(mu d/L) / (phi_max (1 - P/P_cr))``, with phi the
    clamped-pinned mode ``mu (1 - cos mu s) - mu s + sin mu s`` (s in units of L)."""
    mu = math.sqrt(P_CRIT)
    s = np.linspace(0.0, 1.0, 20001)
    phi_max = float(np.max(mu * (1.0 - np.cos(mu * s)) - mu * s + np.sin(mu * s)))
    return 2.0 * phi_max / (abs(math.sin(mu)) * mu**2 * (mu * math.sin(mu) + math.cos(mu)))


@dataclass(frozen=True)
class BeamWeight:
    """The sensor's weight: ``tip`` (N) at the tip, ``per_length`` (N/m) along the beam."""

    tip: float
    per_length: float

    @classmethod
    def of(cls, tip_mass: float, linear_mass: float) -> BeamWeight:
        """From masses (kg and kg/m)."""
        return cls(tip_mass * STANDARD_GRAVITY, linear_mass * STANDARD_GRAVITY)

    def across(self, axis: Vector) -> BeamWeight:
        """The weight's components along ``axis`` (a unit vector across the beam), signed."""
        share = float(GRAVITY @ axis) / STANDARD_GRAVITY
        return BeamWeight(self.tip * share, self.per_length * share)

    def pin_offset(self, EI: float, length: float) -> float:
        """Lateral tip deflection (m) of the free beam under this weight, signed."""
        return (self.tip + 0.375 * self.per_length * length) * length**3 / (3.0 * EI)

    def sag_strains(
        self,
        EI: float,
        fiber_offset: float,
        length: float,
        intervals_from_tip: Vector,
    ) -> tuple[float, ...]:
        """Mean bending strain of each grating, (d0, d1) rows of ``intervals_from_tip`` (G, 2) m
        from the tip, on the free beam (the part inside the tube, d > L, is held straight)."""
        d0 = np.minimum(intervals_from_tip[:, 0], length)
        d1 = np.minimum(intervals_from_tip[:, 1], length)
        moment = self.tip * (d1**2 - d0**2) / 2.0 + self.per_length * (d1**3 - d0**3) / 6.0
        span = intervals_from_tip[:, 1] - intervals_from_tip[:, 0]
        return tuple((-fiber_offset * moment / span / EI).tolist())


def sensing_axis(tangent: Vector, roll: float) -> Vector:
    """The unit vector across the sensor (3,) in the fiber's bending plane, the side the beam
    buckles toward by default: the tube-tip frame's z axis, away from the tube's bend, so the
    fiber bends in the tube's curvature plane (DESIGN: the tube bends toward -z at roll 0).
    Where that is undefined (a sensor along the bend direction, the vertical bench stage) it is
    the base x axis made square to the tangent."""
    bend = np.array([0.0, math.sin(roll), -math.cos(roll)])
    side = -bend + float(bend @ tangent) * tangent
    norm = float(np.linalg.norm(side))
    if norm < 1e-9:
        x = np.array([1.0, 0.0, 0.0])
        side = x - float(x @ tangent) * tangent
        norm = float(np.linalg.norm(side))
    return np.asarray(side / norm)
