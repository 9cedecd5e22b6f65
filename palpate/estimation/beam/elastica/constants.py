"""Landmarks of the clamped-pinned first-mode branch, computed once at import (about 10 ms).

Along the first mode (e/L from 0 up):

* onset, e/L = 0: p = P_CRIT = x1**2 = 20.1907..., x1 the first positive root of tan x = x;
* e/L = E_OVER_L_TIP_NORMAL = 0.3303: the tip angle reaches 90 deg. Past it the arc next to the
  pin runs beyond the plane through the pin normal to the clamp axis, i.e. a bare pin on a flat
  surface normal to the tube would have to penetrate it (the tip sphere delays this a little);
* e/L = E_OVER_L_PEAK = 0.4536: the load peaks at p = P_PEAK = 23.0096 (end of the rising branch);
* e/L = E_OVER_L_MAX = 0.8121: the axial load falls to p = 0, with the tip angle at 212 deg and
  the beam still clear of itself (closest approach of non-adjacent points about 0.06 L).

We end the supported branch at p = 0 (E_OVER_L_MAX). Past it the first mode continues but the
axial load is tensile, which a pushing contact on tissue cannot supply: the tip lifts off. The
pin only reaches the clamp (e/L -> 1) well after that, so p = 0 is the first physical limit of
the model; E_OVER_L_TIP_NORMAL is reported for callers that model a flat surface.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from ._scipy import brentq
from .closed_form import (
    State,
    shortening_ratio,
    state,
    terms,
    wavenumber,
)


def _first_root_tan_x_equals_x() -> float:
    # sin x - x cos x has the roots of tan x = x and no poles; one root in (pi, 3 pi / 2).
    root, converged, _, flag = brentq(
        lambda x: math.sin(x) - x * math.cos(x),
        math.pi,
        1.5 * math.pi,
        xtol=1e-300,
        rtol=1e-15,
        maxiter=200,
    )
    if not converged:  # pragma: no cover - a fixed, smooth bracketed problem
        raise RuntimeError(f"tan x = x root: brentq failed ({flag})")
    return root


def _state_at(k: float) -> State:
    return state(k, wavenumber(k))


def _solve_in_k(f: Callable[[float], float], lo: float, hi: float, what: str) -> float:
    root, converged, _, flag = brentq(f, lo, hi, xtol=1e-300, rtol=1e-15, maxiter=200)
    if not converged:  # pragma: no cover
        raise RuntimeError(f"{what}: brentq failed ({flag})")
    return root


def _modulus_at_zero_load() -> float:
    # p = t^2 (1 - 2 k^2 S^2) = 0  <=>  k S = 1/sqrt(2): phi = -90 deg, the resultant is lateral.
    def f(k: float) -> float:
        z = terms(k, wavenumber(k))
        return float(1.0 - 2.0 * z.m * z.S**2)

    return _solve_in_k(f, 0.8, 0.9, "zero-load point")


def _modulus_at_peak(h: float = 1e-5) -> float:
    def dp(k: float) -> float:
        return float(_state_at(k + h).p - _state_at(k - h).p) / (2.0 * h)

    return _solve_in_k(dp, 0.6, 0.75, "load peak")


def _modulus_at_tip_normal() -> float:
    return _solve_in_k(
        lambda k: float(_state_at(k).tip_angle) - 0.5 * math.pi, 0.5, 0.7, "tip angle 90 deg"
    )


X1: float = _first_root_tan_x_equals_x()
"""First root of tan(x) = x: k L of the clamped-pinned Euler mode (4.4934...)."""
P_CRIT: float = X1 * X1
"""Euler load factor of the clamped-pinned column: P_cr = P_CRIT EI / L**2 (20.1907...)."""


def _mode_slope_integral(mu: float) -> float:
    """J = int_0^1 (cos(mu xi) + mu sin(mu xi) - 1)**2 dxi in closed form (the first mode's
    slope theta(xi) = a (cos + mu sin - 1) shortens the beam by e/L = a**2 J / 2)."""
    s2 = math.sin(2.0 * mu)
    total = (
        mu / 2.0
        + s2 / 4.0
        + mu**2 * (mu / 2.0 - s2 / 4.0)
        + mu
        + mu * math.sin(mu) ** 2
        - 2.0 * math.sin(mu)
        + 2.0 * mu * (math.cos(mu) - 1.0)
    )
    return total / mu


# The clamped-pinned first mode phi(xi) = mu (1 - cos mu xi) - mu xi + sin mu xi, mu = X1: its
# maximum is exactly 2 pi (at mu sin xi + cos xi = 1), which fixes the amplitude-based constants.
MODE_SLOPE_INTEGRAL: float = _mode_slope_integral(X1)
"""J of :func:`_mode_slope_integral` (10.0954), e/L = a**2 J / 2 for slope amplitude a."""
MODE_REACTION: float = X1**3 / (2.0 * math.pi)
"""Pin reaction per unit lateral amplitude A/L of the first mode, in EI/L**2: mu**3 / max(phi)
= mu**3 / (2 pi) (14.4394)."""
MODE_SHORTENING: float = P_CRIT * MODE_SLOPE_INTEGRAL / (8.0 * math.pi**2)
"""c in the bending shortening e = c A**2 / L of the first mode with amplitude A:
(1/2) int phi'**2 dxi / max(phi)**2 = mu**2 J / (8 pi**2) (2.58157)."""

K_MAX: float = _modulus_at_zero_load()
_END = _state_at(K_MAX)
E_OVER_L_MAX: float = float(_END.e_over_L)
"""End of the supported first-mode branch: the axial load reaches zero (0.81209)."""

K_PEAK: float = _modulus_at_peak()
_PEAK = _state_at(K_PEAK)
E_OVER_L_PEAK: float = float(_PEAK.e_over_L)
"""End shortening of the load peak, the end of the rising branch (0.45365, to about 1e-9)."""
P_PEAK: float = float(_PEAK.p)
"""Largest first-mode load factor, P_max = P_PEAK EI / L**2 (23.0096)."""

E_OVER_L_TIP_NORMAL: float = float(_state_at(_modulus_at_tip_normal()).e_over_L)
"""End shortening at which the tip angle reaches 90 deg (0.33029)."""

SHORTENING_RATIO_RANGE: tuple[float, float] = (
    float(shortening_ratio(0.0, X1)),
    E_OVER_L_MAX / K_MAX**2,
)
"""(e/L) / k**2 over the branch: it rises monotonically from 0.95281 (onset) to 1.05685 (p = 0)."""
