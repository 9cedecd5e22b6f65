"""Indentation contact models: Hertz sphere (paper Eq. 13) and rigid flat cylindrical punch.

* Hertz, rigid sphere of radius R on an elastic half-space (modulus E, Poisson ratio nu):
  P = 4/3 E / (1 - nu**2) sqrt(R) delta**1.5, i.e. E = 3/4 P (1 - nu**2) / sqrt(delta**3 R)
  (paper Eq. 13); contact radius a = sqrt(R delta).
* Flat cylindrical punch of radius a (McKee et al. 2011, the paper's ground truth):
  P = 2 a E delta / (1 - nu**2).

All functions are vectorised (numpy broadcasting) and raise ValueError naming the argument for
negative, NaN or infinite inputs. Moduli in Pa, lengths in m, forces in N.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]

MAX_DEPTH_RATIO = 0.1
"""Hertz small-strain limit on delta / R (a / R <= 0.32): past it the parabolic approximation of
the sphere and linear elasticity both err by several percent for soft tissue."""

MAX_CONTACT_RATIO = 0.1
"""Limit on a / h, contact radius over sample thickness. Dimitriadis et al. (2002) give the
bonded thin-sample correction 1 + 1.133 chi + 1.283 chi**2 (chi = a / h): about 12 % at 0.1."""


def _arg(name: str, value: ArrayLike, *, positive: bool = False) -> FloatArray:
    arr = np.asarray(value, dtype=float)
    bad = ~np.isfinite(arr) | ((arr <= 0.0) if positive else (arr < 0.0))
    if np.any(bad):
        first = float(arr[bad].flat[0]) if arr.ndim else float(arr)
        need = "> 0" if positive else ">= 0"
        raise ValueError(f"{name} must be finite and {need}, got {first!r}")
    return arr


def _poisson(nu: ArrayLike) -> FloatArray:
    arr = np.asarray(nu, dtype=float)
    bad = ~np.isfinite(arr) | (arr < 0.0) | (arr > 0.5)
    if np.any(bad):
        first = float(arr[bad].flat[0]) if arr.ndim else float(arr)
        raise ValueError(f"nu must be a Poisson ratio in [0, 0.5], got {first!r}")
    return arr


def hertz_force(E: ArrayLike, delta: ArrayLike, R_tip: ArrayLike, nu: ArrayLike) -> FloatArray:
    """Hertz load P (N) of a sphere of radius ``R_tip`` indenting ``delta`` into modulus ``E``."""
    E_ = _arg("E", E)
    d = _arg("delta", delta)
    R = _arg("R_tip", R_tip, positive=True)
    n = _poisson(nu)
    return np.asarray(4.0 / 3.0 * E_ / (1.0 - n**2) * np.sqrt(R) * d**1.5)


def hertz_modulus(P: ArrayLike, delta: ArrayLike, R_tip: ArrayLike, nu: ArrayLike) -> FloatArray:
    """Paper Eq. (13): E = 3/4 P (1 - nu**2) / sqrt(delta**3 R_tip) (Pa); delta must be > 0."""
    P_ = _arg("P", P)
    d = _arg("delta", delta, positive=True)
    R = _arg("R_tip", R_tip, positive=True)
    n = _poisson(nu)
    return np.asarray(0.75 * P_ * (1.0 - n**2) / np.sqrt(d**3 * R))


def punch_force(E: ArrayLike, delta: ArrayLike, radius: ArrayLike, nu: ArrayLike) -> FloatArray:
    """Flat cylindrical punch load P = 2 a E delta / (1 - nu**2) (N), a = ``radius``."""
    E_ = _arg("E", E)
    d = _arg("delta", delta)
    a = _arg("radius", radius, positive=True)
    n = _poisson(nu)
    return np.asarray(2.0 * a * E_ * d / (1.0 - n**2))


def punch_modulus(P: ArrayLike, delta: ArrayLike, radius: ArrayLike, nu: ArrayLike) -> FloatArray:
    """Flat punch: E = P (1 - nu**2) / (2 a delta) (Pa); delta must be > 0."""
    P_ = _arg("P", P)
    d = _arg("delta", delta, positive=True)
    a = _arg("radius", radius, positive=True)
    n = _poisson(nu)
    return np.asarray(P_ * (1.0 - n**2) / (2.0 * a * d))


def contact_radius(delta: ArrayLike, R_tip: ArrayLike) -> FloatArray:
    """Hertz contact radius a = sqrt(R_tip delta) (m)."""
    return np.asarray(np.sqrt(_arg("delta", delta) * _arg("R_tip", R_tip, positive=True)))


@dataclass(frozen=True)
class HertzValidity:
    """Where Hertz's assumptions hold; arrays broadcast from the inputs.

    Attributes:
        depth_ratio: delta / R_tip.
        contact_ratio: a / h with a = sqrt(R_tip delta); NaN if no thickness was given.
        small_strain: depth_ratio <= max_depth_ratio.
        thick_sample: contact_ratio <= max_contact_ratio (True if no thickness was given).
        ok: both.
        warnings: one sentence per violated condition (with the worst value).
    """

    depth_ratio: FloatArray
    contact_ratio: FloatArray
    small_strain: NDArray[np.bool_]
    thick_sample: NDArray[np.bool_]
    ok: NDArray[np.bool_]
    warnings: tuple[str, ...] = field(default=())


def hertz_validity(
    delta: ArrayLike,
    R_tip: ArrayLike,
    thickness: ArrayLike | None = None,
    *,
    max_depth_ratio: float = MAX_DEPTH_RATIO,
    max_contact_ratio: float = MAX_CONTACT_RATIO,
) -> HertzValidity:
    """Flags and warnings for using Eq. (13) at indentation ``delta`` on a sample ``thickness``."""
    d = _arg("delta", delta)
    R = _arg("R_tip", R_tip, positive=True)
    depth = np.asarray(d / R)
    if thickness is None:
        ratio = np.full(depth.shape, math.nan)
        thick = np.ones(depth.shape, dtype=bool)
    else:
        h = _arg("thickness", thickness, positive=True)
        ratio = np.asarray(np.sqrt(R * d) / h)
        thick = np.asarray(ratio <= max_contact_ratio)
    small = np.asarray(depth <= max_depth_ratio)
    depth, ratio, small, thick = np.broadcast_arrays(depth, ratio, small, thick)
    warnings = []
    if not np.all(small):
        warnings.append(
            f"indentation beyond Hertz's small-strain range: delta/R up to "
            f"{float(np.max(depth)):.3g} > {max_depth_ratio:g}"
        )
    if not np.all(thick):
        warnings.append(
            f"sample too thin for a half-space: a/h up to {float(np.nanmax(ratio)):.3g} > "
            f"{max_contact_ratio:g} (the modulus is overestimated)"
        )
    return HertzValidity(
        depth_ratio=np.asarray(depth),
        contact_ratio=np.asarray(ratio),
        small_strain=np.asarray(small),
        thick_sample=np.asarray(thick),
        ok=np.asarray(small & thick),
        warnings=tuple(warnings),
    )
