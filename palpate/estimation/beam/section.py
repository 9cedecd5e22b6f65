"""Composite cross-section of the sensor: an FBG fiber glued on a row of NiTi wires (paper Fig. 1b).

Geometry: ``wire_count`` wires of radius r_w lie side by side in a row with their centres on
y = 0; the fiber (radius r_f) sits on top touching them, centre at y_f = r_w + r_f. Bending is
about an axis parallel to the row, so every wire is at the same distance from the neutral axis.
The neutral axis is the modulus-weighted centroid,

    y_na = E_f A_f y_f / (E_f A_f + n E_w A_w),

and the second moments about it follow from the parallel-axis theorem:
I_fiber = pi r_f**2 (r_f**2/4 + dy_f**2), I_wires = n pi r_w**2 (r_w**2/4 + y_na**2), which for
n = 4 is the paper's I_wire = pi r_w**2 (r_w**2 + 4 dy_w**2). The fiber's bending strain is
eps = dy_fbg dtheta/ds (paper Eq. 3) with dy_fbg = y_f - y_na.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ...config.schema import SensorConfig
from .elastica.constants import P_CRIT


@dataclass(frozen=True)
class Section:
    """Stiffnesses and geometry of the composite section (SI units).

    Attributes:
        EI: flexural rigidity E_f I_fiber + E_w I_wires (N m**2).
        EA: axial rigidity (N).
        neutral_axis: y of the neutral axis above the wire row's centre line (m).
        fiber_offset: dy_fbg, fiber centre y minus neutral axis y (m); 0 for a bare fiber.
        I_fiber: second moment of the fiber about the neutral axis (m**4).
        I_wires: second moment of all wires about the neutral axis (m**4).
    """

    EI: float
    EA: float
    neutral_axis: float
    fiber_offset: float
    I_fiber: float
    I_wires: float


def _positive(name: str, value: float) -> float:
    value = float(value)
    if not (math.isfinite(value) and value > 0.0):
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return value


def composite_section(
    fiber_radius: float,
    fiber_modulus: float,
    wire_radius: float,
    wire_modulus: float,
    wire_count: int,
) -> Section:
    """Section of a fiber on ``wire_count`` wires (SI inputs; ``wire_count`` = 0: a bare fiber)."""
    r_f = _positive("fiber_radius", fiber_radius)
    E_f = _positive("fiber_modulus", fiber_modulus)
    r_w = _positive("wire_radius", wire_radius)
    E_w = _positive("wire_modulus", wire_modulus)
    if isinstance(wire_count, bool) or int(wire_count) != wire_count or wire_count < 0:
        raise ValueError(f"wire_count must be an integer >= 0, got {wire_count!r}")
    n = int(wire_count)
    A_f = math.pi * r_f**2
    A_w = math.pi * r_w**2
    y_f = r_w + r_f
    EA = E_f * A_f + n * E_w * A_w
    y_na = E_f * A_f * y_f / EA
    dy_f = y_f * (n * E_w * A_w) / EA  # = y_f - y_na without the cancellation (0 if n == 0)
    I_fiber = A_f * (r_f**2 / 4.0 + dy_f**2)
    I_wires = n * A_w * (r_w**2 / 4.0 + y_na**2)
    return Section(
        EI=E_f * I_fiber + E_w * I_wires,
        EA=EA,
        neutral_axis=y_na,
        fiber_offset=dy_f,
        I_fiber=I_fiber,
        I_wires=I_wires,
    )


def across_rigidity(
    fiber_radius: float,
    fiber_modulus: float,
    wire_radius: float,
    wire_modulus: float,
    wire_count: int,
) -> float:
    """EI (N m^2) for bending *across* the fiber's plane, about the axis through the fiber and
    the row's middle: the wires side by side at x = (2i - (n - 1)) r_w, the fiber at x = 0. A beam
    buckles about its softest axis; the gratings see only the bending in their own plane
    (:class:`Section`'s EI), so a design must be stiffer across (``design``)."""
    r_f = _positive("fiber_radius", fiber_radius)
    r_w = _positive("wire_radius", wire_radius)
    n = int(wire_count)
    ei = _positive("fiber_modulus", fiber_modulus) * math.pi * r_f**4 / 4.0
    e_w = _positive("wire_modulus", wire_modulus)
    for i in range(n):
        x = (2 * i - (n - 1)) * r_w
        ei += e_w * (math.pi * r_w**4 / 4.0 + math.pi * r_w**2 * x * x)
    return ei


def euler_load(EI: float, L: float) -> float:
    """Critical load of the clamped-pinned column, P_cr = P_CRIT EI / L**2 (P_CRIT = 20.1907)."""
    return P_CRIT * _positive("EI", EI) / _positive("L", L) ** 2


__all__ = ["P_CRIT", "Section", "across_rigidity", "composite_section", "euler_load"]


def sensor_section(sensor: SensorConfig) -> Section:
    """The composite section (EI, EA, fiber offset) of a configured sensor."""
    return composite_section(
        sensor.fiber_radius,
        sensor.fiber_modulus,
        sensor.wire_radius,
        sensor.wire_modulus,
        sensor.wire_count,
    )


def grating_intervals(
    sensor: SensorConfig, exposed_length: float | None = None
) -> NDArray[np.float64]:
    """Arc-length intervals (m) of the used gratings, shape (N, 2), ``s = L - distance_from_tip``.

    Rows follow ``sensor.used_gratings``; each row is ``(s_start, s_end)`` with start < end.
    A grating (partly) inside the tube, s < 0, is kept: the caller decides what that means.
    """
    L = sensor.exposed_length if exposed_length is None else exposed_length
    centres = L - np.asarray(sensor.grating_centres_from_tip(), dtype=np.float64)
    half = sensor.grating_length / 2
    return np.stack([centres - half, centres + half], axis=1)
