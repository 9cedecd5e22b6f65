"""The sensor's own weight held across it: the sag a design must carry.

A sensor pointing other than straight down or up carries the weight of its tip (and of the beam)
across it. As a cantilever before contact it sags ``w = (W + 3 q L / 8) L^3 / (3 EI)`` (a tip
load W and a uniform load q, the 3/8 matching the uniform load's tip deflection); once the tip
is pinned on the tissue where it sagged to, that offset is a bow the load amplifies as it nears
P_cr. With ``EI = P_cr L^2 / 20.19`` the tip's share is ``w / L = (20.19 / 3) W / P_cr``: the
sag is set by the weight against the buckling load, whatever the length. The paper's sensor
(0.21 g tip, P_cr 1.35 N) sags 1.1 % of L; a mN sensor for soft tissue with a printed tip of
0.05 g sags a sixth of its length (docs/lung.md), which no straight-beam reading of its strains
carries. The check only reports: such a sensor is still usable pointing vertically (the bench's
stage) or rolled so its fiber bends in a horizontal plane.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]

STANDARD_GRAVITY = 9.80665  # m/s^2
SAG_LIMIT = 0.015
"""sag / L a design may have: about the paper's sensor's (1.1 %), whose estimates carry it."""
SILICA_DENSITY = 2200.0  # kg/m^3, the fiber
NITI_DENSITY = 6450.0  # kg/m^3, the wires
TIP_DENSITY = 1200.0  # kg/m^3, a printed resin sphere


def linear_mass(fiber_radius: float, wire_count: int, wire_radius: float) -> float:
    """The beam's mass per length (kg/m): the fiber and its wires."""
    return math.pi * (SILICA_DENSITY * fiber_radius**2 + NITI_DENSITY * wire_count * wire_radius**2)


def sag_share(
    tip_mass: ArrayLike, linear_mass: ArrayLike, EI: ArrayLike, length: ArrayLike
) -> FloatArray:
    """sag / L of the cantilever held across (see the module docstring), elementwise."""
    m, q = np.asarray(tip_mass, dtype=float), np.asarray(linear_mass, dtype=float)
    EI_, L = np.asarray(EI, dtype=float), np.asarray(length, dtype=float)
    return np.asarray((m + 0.375 * q * L) * STANDARD_GRAVITY * L**2 / (3.0 * EI_))


@dataclass(frozen=True)
class WeightCheck:
    """The sag (m) of a sensor held horizontally, over its exposed length, and whether it is
    within :data:`SAG_LIMIT`; ``tip_mass_limit`` (kg) is the heaviest tip that would be."""

    sag: float
    sag_over_length: float
    tip_mass_limit: float

    @property
    def ok(self) -> bool:
        return self.sag_over_length <= SAG_LIMIT

    def as_dict(self) -> dict[str, float | bool]:
        return {
            "sag_mm": self.sag * 1e3,
            "sag_over_length": self.sag_over_length,
            "limit": SAG_LIMIT,
            "tip_mass_limit_g": self.tip_mass_limit * 1e3,
            "ok": self.ok,
        }


def weight_check(tip_mass: float, linear_mass: float, EI: float, length: float) -> WeightCheck:
    """The sag under the tip's mass (kg) and the beam's (kg/m) of a beam of rigidity ``EI``
    (N m^2) and exposed ``length`` (m); ValueError for a non-positive EI or length or a
    negative mass."""
    if not (EI > 0 and length > 0 and tip_mass >= 0 and linear_mass >= 0):
        raise ValueError("EI and length must be > 0, the masses >= 0")
    g = STANDARD_GRAVITY
    compliance = length**3 / (3.0 * EI)  # tip deflection per N at the tip
    sag = (tip_mass * g + 0.375 * linear_mass * g * length) * compliance
    budget = SAG_LIMIT * length / compliance - 0.375 * linear_mass * g * length
    return WeightCheck(sag, sag / length, max(budget, 0.0) / g if math.isfinite(budget) else 0.0)
