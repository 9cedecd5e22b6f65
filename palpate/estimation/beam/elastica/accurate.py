"""Reference-grade first-mode solver: closed form in elliptic functions, bracketed 1-D roots.

For a given e/L we solve 2 log k + log(Etilde(k)) = log(e/L) for the modulus k, where
Etilde = (e/L) / k**2 comes from the closed form (see ``closed_form``) with t = t(k) from its own
bracketed root. Working in log k with the O(1) ratio Etilde is what keeps the problem well
conditioned at onset: Etilde only moves from 0.9528 to 1.0568 over the whole branch, so
k = sqrt((e/L) / Etilde) is bracketed within a few percent for any e/L, including 1e-8 and 0.
Cost: about 2 ms per state (a brentq on k whose every step runs a brentq on t).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from ._scipy import brentq, ellipk
from .closed_form import shortening_ratio, state, wavenumber
from .constants import E_OVER_L_MAX, K_MAX, SHORTENING_RATIO_RANGE, X1
from .errors import ElasticaConvergenceError, checked_e_over_L
from .solution import ElasticaSolution

RTOL = 1e-15
MAXITER = 200


def modulus(e_over_L: float, *, rtol: float = RTOL, maxiter: int = MAXITER) -> float:
    """Elliptic modulus k of the first-mode state with end shortening ``e_over_L`` (scalar).

    Raises ElasticaConvergenceError (naming e/L and the failed step) if a root is not found.
    """
    e = float(checked_e_over_L(e_over_L, E_OVER_L_MAX))
    if e == 0.0:
        return 0.0
    if e == E_OVER_L_MAX:
        return K_MAX
    ratio_lo, ratio_hi = SHORTENING_RATIO_RANGE
    lo = math.sqrt(e / ratio_hi) * (1.0 - 1e-9)
    hi = min(math.sqrt(e / ratio_lo) * (1.0 + 1e-9), K_MAX)
    log_e = math.log(e)

    def f(k: float) -> float:
        return 2.0 * math.log(k) + math.log(float(shortening_ratio(k, wavenumber(k)))) - log_e

    f_hi = f(hi)
    if f_hi < 0.0:  # e within rounding of E_OVER_L_MAX
        if f_hi > -1e-13:
            return hi
        raise ElasticaConvergenceError(
            f"accurate: e_over_L={e!r} not bracketed by k in [{lo!r}, {hi!r}] (f(hi)={f_hi:.3g})"
        )
    k, converged, iterations, flag = brentq(f, lo, hi, xtol=1e-300, rtol=rtol, maxiter=maxiter)
    if not converged:
        raise ElasticaConvergenceError(
            f"accurate: brentq on the modulus for e_over_L={e!r} stopped after {iterations} "
            f"iterations ({flag})"
        )
    return k


def solve(e_over_L: ArrayLike, *, rtol: float = RTOL, maxiter: int = MAXITER) -> ElasticaSolution:
    """First-mode states for ``e_over_L`` (any shape; loops over the unique values).

    Accuracy: relative 1e-13 or better in p, r, tip angle and curvatures over [0, E_OVER_L_MAX]
    (checked against solve_bvp and a DOP853 re-integration in the tests).
    """
    e = checked_e_over_L(e_over_L, E_OVER_L_MAX)
    unique, inverse = np.unique(e.ravel(), return_inverse=True)
    k_unique = np.array([modulus(v, rtol=rtol, maxiter=maxiter) for v in unique])
    t_unique = np.array(
        [X1 if k == 0.0 else wavenumber(float(k), rtol=rtol, maxiter=maxiter) for k in k_unique]
    )
    k = k_unique[inverse].reshape(e.shape)
    t = t_unique[inverse].reshape(e.shape)
    st = state(k, t)
    return ElasticaSolution(
        e_over_L=e,
        p=st.p,
        r=st.r,
        tip_angle=st.tip_angle,
        modulus=k,
        wavenumber=t,
        u0=np.asarray(ellipk(k * k) - t),
        method="accurate",
    )
