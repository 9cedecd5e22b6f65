"""The clamped-pinned inflectional elastica in Jacobi elliptic functions.

Dimensionless form (arc s in units of L, loads in units of EI/L**2) of paper Eq. (7):

    theta'' + p sin(theta) + r cos(theta) = 0,  theta(0) = 0,  theta'(1) = 0,  y(1) = 0.

With F = p**2 + r**2 = t**2 and phi = atan2(r, p), psi = theta + phi obeys the pendulum equation
psi'' + F sin(psi) = 0, whose inflectional solution is sin(psi/2) = k sn(u | k**2), u = u0 + t s,
curvature theta' = 2 k t cn(u). The pin (zero moment) is the inflection point u = K(k), so
u0 = K - t; on the first mode u0 lies in (-2K, -K), i.e. w = 3K - t lies in (0, K), and the only
other inflection point is u = -K, at s = (t - 2K) / t (about 0.30 near onset).

Everything is written in the quantities S = sn(w), C = cn(w), Dn = dn(w) of that short argument w
(sn(u0) = -S, cn(u0) = -C, cos(phi/2) = Dn), and in Q = integral of sn**2 over [u0, K], evaluated
through Carlson's R_D so that it never forms u - E(u) (which cancels as k -> 0). Dividing the pin
condition y(1) = 0 and the end shortening e by their exact leading powers of k leaves

    g(k, t)   = S Dn (t - 2 k**2 Q) - C (1 - 2 k**2 S**2)                 (= 0 on a solution)
    e / k**2  = (2 / t) [t S**2 + Q (1 - 2 k**2 S**2) - 2 S C Dn]
    p = t**2 (1 - 2 k**2 S**2),   r = -2 t**2 k S Dn,   theta(1) = 2 (asin k + asin(k S)),

all O(1) and smooth in k**2 at k = 0, where g reduces to sin t - t cos t (tan t = t: the Euler
load t**2 = 20.19). That is why the solver is parameterised by k and stays well conditioned at
onset: R and the curvatures come out proportional to k ~ sqrt(e/L) with full relative precision.

Sign convention: k > 0 is the mirror image in which the beam bows toward -y, the tip angle and the
curvature of the main lobe (from the inflection point to the pin) are positive, and r < 0. The
other buckling direction is (theta, r, y) -> -(theta, r, y).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._scipy import brentq, ellipj, ellipk, elliprd
from .errors import ElasticaConvergenceError

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Terms:
    """The short-argument quantities of one or more (k, t) pairs (arrays of a common shape)."""

    m: FloatArray  # k**2
    S: FloatArray  # sn(w), w = 3K - t
    C: FloatArray  # cn(w)
    Dn: FloatArray  # dn(w)
    Q: FloatArray  # integral of sn(u)**2 du over [u0, K]


def terms(k: ArrayLike, t: ArrayLike) -> Terms:
    """S, C, Dn and Q for modulus ``k`` and wavenumber ``t`` (broadcast; shapes as numpy)."""
    k_arr = np.asarray(k, dtype=float)
    m = k_arr * k_arr
    K = ellipk(m)
    w = 3.0 * K - np.asarray(t, dtype=float)
    S, C, Dn, _ = ellipj(w, m)
    # J(v) = integral of sn^2 over [0, v]; J(K) = R_D(0, 1-m, 1)/3, J(w) = S^3 R_D(C^2, Dn^2, 1)/3
    # (w in [0, K]); by the symmetries of sn, integral over [u0, K] = 3 J(K) - J(w).
    J_K = elliprd(0.0, 1.0 - m, 1.0) / 3.0
    J_w = S**3 * elliprd(C * C, Dn * Dn, 1.0) / 3.0
    return Terms(m=m, S=S, C=C, Dn=Dn, Q=3.0 * J_K - J_w)


def pin_residual(k: ArrayLike, t: ArrayLike) -> FloatArray:
    """g(k, t): the pin-on-axis condition y(1) = 0 divided by its leading factor 2 k / t."""
    z = terms(k, t)
    t_arr = np.asarray(t, dtype=float)
    return np.asarray(z.S * z.Dn * (t_arr - 2.0 * z.m * z.Q) - z.C * (1.0 - 2.0 * z.m * z.S**2))


def shortening_ratio(k: ArrayLike, t: ArrayLike) -> FloatArray:
    """(e/L) / k**2 at a solution (k, t): an O(1) quantity, 0.9528 at onset, 1.0568 at p = 0."""
    return _shortening_ratio(terms(k, t), np.asarray(t, dtype=float))


def _shortening_ratio(z: Terms, t: FloatArray) -> FloatArray:
    bracket = t * z.S**2 + z.Q * (1.0 - 2.0 * z.m * z.S**2) - 2.0 * z.S * z.C * z.Dn
    return np.asarray(2.0 / t * bracket)


def wavenumber(k: float, *, rtol: float = 1e-15, maxiter: int = 200) -> float:
    """First-mode t = sqrt(p**2 + r**2) for modulus k in [0, 1): the root of g(k, .) in [2K, 3K].

    g > 0 at t = 2K (w = K) and g < 0 at t = 3K (w = 0) on the whole supported branch, so a
    bracketed solve cannot wander onto another mode. Raises ElasticaConvergenceError otherwise.
    """
    K = float(ellipk(k * k))
    lo, hi = 2.0 * K, 3.0 * K
    f_lo, f_hi = float(pin_residual(k, lo)), float(pin_residual(k, hi))
    if not (f_lo > 0.0 > f_hi):
        raise ElasticaConvergenceError(
            f"wavenumber: pin condition not bracketed on [2K, 3K] for modulus k={k!r} "
            f"(g={f_lo:.3g}, {f_hi:.3g}); k is beyond the first-mode branch"
        )
    root, converged, iterations, flag = brentq(
        lambda t: float(pin_residual(k, t)), lo, hi, xtol=1e-300, rtol=rtol, maxiter=maxiter
    )
    if not converged:
        raise ElasticaConvergenceError(
            f"wavenumber: brentq on the pin condition for k={k!r} stopped after {iterations} "
            f"iterations ({flag})"
        )
    return root


@dataclass(frozen=True)
class State:
    """Loads and end values of solutions (k, t); arrays of a common shape."""

    k: FloatArray
    t: FloatArray
    e_over_L: FloatArray  # noqa: N815 - the paper's e/L
    p: FloatArray
    r: FloatArray
    tip_angle: FloatArray


def state(k: ArrayLike, t: ArrayLike) -> State:
    """Evaluate e/L, p, r and the tip angle for solutions (k, t) (broadcast)."""
    k_arr, t_arr = np.broadcast_arrays(np.asarray(k, dtype=float), np.asarray(t, dtype=float))
    z = terms(k_arr, t_arr)
    e_over_k2 = _shortening_ratio(z, t_arr)
    return State(
        k=k_arr,
        t=t_arr,
        e_over_L=z.m * e_over_k2,
        p=t_arr**2 * (1.0 - 2.0 * z.m * z.S**2),
        r=-2.0 * t_arr**2 * k_arr * z.S * z.Dn,
        tip_angle=2.0 * (np.arcsin(k_arr) + np.arcsin(k_arr * z.S)),
    )
