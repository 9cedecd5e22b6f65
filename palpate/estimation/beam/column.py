"""The clamped beam-column with a lateral load at its free tip: the shape the load's lean gives
the gratings (``estimation.pose.misalignment``, ``estimation.pose.slip_path``).

A load ``P`` along the axis and ``P tan(gamma)`` across it bend the exposed length ``L``
(``k = sqrt(P / EI)``, ``d`` the distance from the tip) as::

    kappa(d) = tan(gamma) k sin(k d) / cos(k L)          (0 <= d <= L; straight inside the tube)

which diverges at the free tip's capacity ``(pi/2)^2 EI / L^2``.

    >>> import numpy as np
    >>> spans = np.array([[0.001, 0.002], [0.010, 0.011]])  # two gratings, m from the tip
    >>> lateral_shape(np.array([0.0, 0.01]), 0.03, spans, EI=1e-5, fiber_offset=2e-4).shape
    (2, 2)
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


def lateral_shape(
    load: FloatArray,
    length: FloatArray | float,
    from_tip: FloatArray,
    EI: float,
    fiber_offset: float,
) -> FloatArray:
    """h (N, G): grating-mean strain per unit tan(gamma) of a clamped beam-column loaded at its
    free tip by ``load`` (N,) along the axis and ``load tan(gamma)`` across it.

    ``from_tip`` (G, 2): each grating's (d0, d1), metres from the tip; the part beyond L is
    inside the tube (straight). ``length``: L (m), one or (N,). Loads must be below the
    capacity (kL < pi/2).
    """
    return lateral_shape_by_grating(load, length, from_tip, EI, fiber_offset).T


def lateral_shape_by_grating(
    load: FloatArray,
    length: FloatArray | float,
    from_tip: FloatArray,
    EI: float,
    fiber_offset: float,
) -> FloatArray:
    """:func:`lateral_shape` grating-major, (G, N): the same arithmetic element for element
    (the fits' sums over a few gratings run as whole-array additions on this layout)."""
    k = np.sqrt(np.maximum(load, 0.0) / EI)[None, :]
    length = np.broadcast_to(np.asarray(length, dtype=np.float64), k.shape[1:])[None, :]
    d0 = np.minimum(from_tip[:, 0, None], length)
    d1 = np.minimum(from_tip[:, 1, None], length)
    span = (from_tip[:, 1] - from_tip[:, 0])[:, None]
    # int k sin(k d) dd = cos(k d0) - cos(k d1), written without the cancellation at small k
    integral = 2.0 * np.sin(0.5 * k * (d0 + d1)) * np.sin(0.5 * k * (d1 - d0))
    return np.asarray(-fiber_offset * integral / (span * np.cos(k * length)))


def capacity(EI: float, length: float) -> float:
    """(pi/2)^2 EI / L^2 (N): the free-tip beam-column's axial load at which it diverges."""
    return (0.5 * math.pi) ** 2 * EI / length**2
