"""The paper's solver (Eqs. 8-11), kept as an honest baseline: shoot on kappa = P / R.

For a trial kappa, integrate theta'' + kappa sin(theta) + cos(theta) = 0 in t = s sqrt(R/EI) from
the clamp (theta = 0, theta' = a) with solve_ivp until the moment vanishes the second time
(theta' = 0 at the pin; the first zero is the inflection point near s = 0.3 L), and adjust a by a
secant iteration until the pin is on the axis, eta(t_end) = 0 (Eq. 11). Then r = t_end**2,
p = kappa r, and e/L = 1 - xi(t_end) / t_end. An outer root finder on kappa matches the requested
e/L. Both roots are bracketed by a geometric scan from the linearised (small-deflection) guess,
and the inner one is warm-started from the previous kappa, as a careful user of the paper's
method would do; an over-the-top pendulum (no second zero of the moment) counts as overshoot.

The paper's R > 0 is the mirror image of our convention (see ``closed_form``); results are
mirrored back. Near onset kappa ~ 1/sqrt(e/L) -> infinity and t_end -> 0, which is where the
method loses accuracy and fails; failures are counted and reported, never hidden: ``shoot``
returns per-state ``success`` flags and messages, ``solve`` raises ElasticaConvergenceError.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._scipy import brentq, solve_ivp
from .constants import E_OVER_L_MAX, P_CRIT, X1
from .errors import (
    ElasticaConvergenceError,
    checked_e_over_L,
    checked_unit_interval,
)

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class ShootingOptions:
    """Integrator and iteration settings (defaults: a careful but ordinary user of the paper)."""

    method: str = "RK45"
    rtol: float = 1e-10
    atol: float = 1e-12
    xtol: float = 1e-12  # relative tolerance of both root finders (on a and on kappa)
    maxiter: int = 60  # per bracket scan and per root finder


@dataclass(frozen=True)
class Shot:
    """One shooting solve: the state if ``success``, else NaNs and the reason in ``message``."""

    success: bool
    message: str
    p: float = math.nan
    r: float = math.nan
    tip_angle: float = math.nan
    kappa: float = math.nan
    t_end: float = math.nan
    profile: Callable[[FloatArray], FloatArray] | None = None  # theta at t (paper mirror)


class _ShootingError(Exception):
    """Internal: one shooting step failed; turned into a failed ``Shot``."""


def _linear_reaction(e: float) -> float:
    """Small-deflection estimate of r for e/L = e (initial guess only)."""
    s = np.linspace(0.0, 1.0, 2001)
    mode = np.cos(X1 * s) - 1.0 + X1 * np.sin(X1 * s)
    integral = float(np.sum((mode[1:] ** 2 + mode[:-1] ** 2) * 0.5 * np.diff(s)))
    return P_CRIT * math.sqrt(2.0 * e / integral)


def _integrate(kappa: float, a: float, opts: ShootingOptions) -> Any:
    def rhs(_t: float, y: FloatArray) -> list[float]:
        th, dth = y[0], y[1]
        return [dth, -kappa * math.sin(th) - math.cos(th), math.sin(th), math.cos(th)]

    def pin(_t: float, y: FloatArray) -> float:
        return float(y[1])

    pin.terminal = True  # type: ignore[attr-defined]
    pin.direction = 1.0  # type: ignore[attr-defined]
    t_max = 4.0 * math.pi / math.sqrt(kappa) + 4.0 * math.pi
    sol = solve_ivp(
        rhs,
        (0.0, t_max),
        [0.0, a, 0.0, 0.0],
        method=opts.method,
        rtol=opts.rtol,
        atol=opts.atol,
        events=pin,
        dense_output=True,
    )
    if sol.status != 1 or len(sol.t_events[0]) == 0:
        raise _ShootingError(f"no pin (second zero of the moment) by t={t_max:.3g}, a={a:.3g}")
    return sol


def _bracket(
    f: Callable[[float], float], x: float, factor: float, opts: ShootingOptions, what: str
) -> tuple[float, float]:
    """Geometric scan from ``x`` for lo < hi with f(lo) < 0 < f(hi); f may be +inf (overshoot)."""
    fx = f(x)
    lo, hi = (x, x * factor) if fx < 0.0 else (x / factor, x)
    f_lo, f_hi = (fx, f(hi)) if fx < 0.0 else (f(lo), fx)
    for _ in range(opts.maxiter):
        if f_lo < 0.0 < f_hi:
            break
        if f_lo >= 0.0:
            lo, hi, f_hi = lo / factor, lo, f_lo
            f_lo = f(lo)
        else:
            lo, hi, f_lo = hi, hi * factor, f_hi
            f_hi = f(hi)
    else:
        raise _ShootingError(f"{what}: no sign change found in {opts.maxiter} scan steps")
    for _ in range(opts.maxiter):  # pull an overshooting (+inf) end back to a finite value
        if math.isfinite(f_hi):
            return lo, hi
        mid = math.sqrt(lo * hi)
        f_mid = f(mid)
        if f_mid < 0.0:
            lo = mid
        else:
            hi, f_hi = mid, f_mid
    raise _ShootingError(f"{what}: could not bracket away from the overshooting region")


def _root(
    f: Callable[[float], float], lo: float, hi: float, opts: ShootingOptions, what: str
) -> float:
    def finite(x: float) -> float:
        value = f(x)
        if not math.isfinite(value):
            raise _ShootingError(f"{what}: residual not finite at {x:.6g}")
        return value

    x, converged, iterations, flag = brentq(
        finite, lo, hi, xtol=1e-300, rtol=max(opts.xtol, 1e-15), maxiter=opts.maxiter
    )
    if not converged:
        raise _ShootingError(f"{what}: brentq stopped after {iterations} iterations ({flag})")
    return x


class _Shooter:
    """Inner shooting on a = theta'(0) for a given kappa, warm-started from the last solution."""

    def __init__(self, opts: ShootingOptions) -> None:
        self.opts = opts
        self.a_last: float | None = None

    def eta_end(self, kappa: float, a: float) -> float:
        try:
            sol = _integrate(kappa, a, self.opts)
        except _ShootingError:
            return math.inf  # the pendulum went over the top: a is too large
        return float(sol.y_events[0][0][2])

    def solve(self, kappa: float) -> Any:
        what = f"shooting on theta'(0) for kappa={kappa:.6g}"
        guess = self.a_last or math.sqrt(P_CRIT / kappa)  # linear theory: a = sqrt(r)
        lo, hi = _bracket(lambda a: self.eta_end(kappa, a), guess, 1.25, self.opts, what)
        a = _root(lambda a: self.eta_end(kappa, a), lo, hi, self.opts, what)
        self.a_last = a
        return _integrate(kappa, a, self.opts)


def shoot_one(e_over_L: float, opts: ShootingOptions | None = None) -> Shot:
    """Solve one state by the paper's method; failures come back as ``Shot(success=False)``."""
    opts = opts or ShootingOptions()
    e = float(checked_e_over_L(e_over_L, E_OVER_L_MAX))
    if e == 0.0:
        return Shot(False, "shooting: e_over_L=0 is the unbuckled state (kappa = infinity)")
    shooter = _Shooter(opts)

    def log_e_mismatch(kappa: float) -> float:
        sol = shooter.solve(kappa)
        t_end = float(sol.t_events[0][0])
        shortening = 1.0 - float(sol.y_events[0][0][3]) / t_end
        if shortening <= 0.0:
            return -math.inf if kappa > 0 else math.inf
        return -(math.log(shortening) - math.log(e))  # increasing in kappa

    kappa0 = P_CRIT / _linear_reaction(e)
    try:
        lo, hi = _bracket(log_e_mismatch, kappa0, 2.0, opts, "bracketing kappa")
        kappa = _root(log_e_mismatch, lo, hi, opts, "shooting on kappa")
        sol = shooter.solve(kappa)
    except _ShootingError as exc:
        return Shot(False, f"shooting: e_over_L={e!r}: {exc}")
    t_end = float(sol.t_events[0][0])
    r = t_end**2
    theta_pin = float(sol.y_events[0][0][0])

    def profile(t: FloatArray, _sol: Any = sol) -> FloatArray:
        return np.asarray(_sol.sol(t)[0], dtype=float)

    return Shot(True, "converged", kappa * r, -r, -theta_pin, kappa, t_end, profile)


@dataclass(frozen=True)
class ShootingSolution:
    """States from the paper's method (shape of ``e_over_L``); NaN only where not ``success``."""

    e_over_L: FloatArray  # noqa: N815 - the paper's e/L
    p: FloatArray
    r: FloatArray
    tip_angle: FloatArray
    success: NDArray[np.bool_]
    messages: tuple[str, ...]  # one per state, flattened (C order)
    shots: tuple[Shot, ...]
    method: str = "shooting"

    @property
    def failures(self) -> int:
        return int(np.count_nonzero(~self.success))

    def mean_curvature(self, s0: ArrayLike, s1: ArrayLike) -> FloatArray:
        """Mean of L dtheta/ds over [s0, s1] from the integrated profile (broadcast with e/L)."""
        a = checked_unit_interval(s0, "s0")
        b = checked_unit_interval(s1, "s1")
        index = np.arange(self.e_over_L.size).reshape(self.e_over_L.shape)
        idx, a, b = np.broadcast_arrays(index, a, b)
        out = np.full(idx.shape, math.nan)
        for i in np.unique(idx):
            shot = self.shots[int(i)]
            if shot.profile is None:
                continue
            sel = idx == i
            th_a = shot.profile(a[sel] * shot.t_end)
            th_b = shot.profile(b[sel] * shot.t_end)
            out[sel] = -(th_b - th_a) / (b[sel] - a[sel])
        return out


def shoot(e_over_L: ArrayLike, opts: ShootingOptions | None = None) -> ShootingSolution:
    """The paper's method on every state of ``e_over_L``; counts failures instead of raising."""
    e = checked_e_over_L(e_over_L, E_OVER_L_MAX)
    shots = tuple(shoot_one(float(v), opts) for v in e.ravel())

    def field(name: str) -> FloatArray:
        return np.array([getattr(s, name) for s in shots], dtype=float).reshape(e.shape)

    return ShootingSolution(
        e_over_L=e,
        p=field("p"),
        r=field("r"),
        tip_angle=field("tip_angle"),
        success=np.array([s.success for s in shots], dtype=bool).reshape(e.shape),
        messages=tuple(s.message for s in shots),
        shots=shots,
    )


def solve(e_over_L: ArrayLike, opts: ShootingOptions | None = None) -> ShootingSolution:
    """Like ``shoot``, but raise ElasticaConvergenceError naming the failed states."""
    result = shoot(e_over_L, opts)
    if result.failures:
        flags = result.success.ravel()
        failed = [m for m, ok in zip(result.messages, flags, strict=True) if not ok]
        raise ElasticaConvergenceError(
            f"shooting failed on {result.failures} of {result.success.size} states: "
            + "; ".join(failed[:3])
        )
    return result
