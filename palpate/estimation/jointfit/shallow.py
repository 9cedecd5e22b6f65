"""How the record's modulus changes with depth: the shallow half's modulus over the whole's.

A homogeneous sample follows its contact law at every depth, so the modulus the loading's first
half (0 < delta <= delta_max / 2) asks for is the whole record's. Under a buried stiff sphere the
contact feels more of it as it widens, so the shallow half reads lower when the sphere lies
deep and about the same or higher when it lies near the surface: the rate at which the apparent
modulus rises with the indentation is set by how deep it lies (``maps.depth`` reads it).

With the contact x0 and the load offset P0 held at the fit's, E is linear in each half and has
a closed form under the fit's frozen weights w (the last robust step's)::

    E(D) = sum w f P / sum w f^2   over 0 < delta <= D

The log ratio's sd has two parts: the load's noise, ``s^2 (1 / (S_h E_h^2) - 1 / (S E^2))``
for the nested least-squares estimates (``S = sum w f^2``; the whole record holds the half, so
their covariance is the whole's variance), and the contact's, the ratio's slope in x0 times
x0's sd from its interval (a later contact makes every depth shallower, the shallow half's
most). Usage (inside the fit's recipe, once the estimate is final)::

    shallow = shallow_ratio(fit, record.force, weights, noise.scale2, contact_sd)
    shallow.log_ratio, shallow.sd     # ~0 +- 0.035 on a homogeneous sample
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .refine import Refined

FloatArray = NDArray[np.float64]

HALF = 0.5  # the shallow part: depths up to this share of the deepest
MIN_SHALLOW_POINTS = 10
CONTACT_STEP = 1e-6  # m: the x0 step of the ratio's slope


@dataclass(frozen=True)
class Shallow:
    """log(E over the loading's first half / E over all of it) and its sd; ``depth``: the
    half's deepest indentation (m)."""

    log_ratio: float
    sd: float
    depth: float


def shallow_ratio(
    fit: Refined,
    force: FloatArray,
    weights: FloatArray,
    scale2: float,
    contact_sd: float,
) -> Shallow | None:
    """The shallow half's modulus over the whole's for the final ``fit`` on loads ``force``
    (N) with the frozen ``weights`` and noise inflation ``scale2``; ``contact_sd``: x0's sd
    (m). None when the half holds fewer than :data:`MIN_SHALLOW_POINTS` samples or a sum
    is not positive."""
    deepest = float(fit.depth.max())
    load = force - fit.load_offset
    half = HALF * deepest

    def moduli(shift: float) -> tuple[float, float, float, float] | None:
        depth = fit.depth - shift
        past = depth > 0.0
        f = np.zeros_like(depth)
        f[past] = fit.hypothesis.law.shape(depth[past])[0]
        shallow = past & (depth <= half)
        if np.count_nonzero(shallow) < MIN_SHALLOW_POINTS:
            return None
        s_all = float(np.sum(weights * f * f))
        s_half = float(np.sum((weights * f * f)[shallow]))
        if not (s_all > 0.0 and s_half > 0.0):
            return None
        e_all = float(np.sum(weights * f * load)) / s_all
        e_half = float(np.sum((weights * f * load)[shallow])) / s_half
        return e_half, e_all, s_half, s_all

    now = moduli(0.0)
    later = moduli(CONTACT_STEP)
    if now is None or later is None or min(now[:2]) <= 0.0 or min(later[:2]) <= 0.0:
        return None
    e_half, e_all, s_half, s_all = now
    ratio = math.log(e_half / e_all)
    slope = (math.log(later[0] / later[1]) - ratio) / CONTACT_STEP
    noise = max(scale2 * (1.0 / (s_half * e_half**2) - 1.0 / (s_all * e_all**2)), 0.0)
    return Shallow(ratio, math.sqrt(noise + (slope * contact_sd) ** 2), half)
