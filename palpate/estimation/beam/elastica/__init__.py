"""Clamped-pinned elastica (paper Eqs. 7-11), dimensionless: the public entry point.

``post_buckling(e_over_L, method)`` returns the first-mode post-buckling state for an end
shortening ratio e/L (scalar or array): ``p = P L**2/EI``, ``r = R L**2/EI``, ``tip_angle`` and
``mean_curvature(s0, s1)`` (mean of L dtheta/ds over s/L in [s0, s1], s from the clamp, 0, to the
pin, 1). Methods:

* ``"accurate"``: closed form in Jacobi elliptic functions with bracketed 1-D roots in the modulus;
  relative error about 1e-13, ~2 ms per state; the reference.
* ``"fast"``: Chebyshev surrogate of the accurate solution, vectorised; relative error about
  1e-12 (p error measured against max(|p|, 1)), ~2 us per state with three grating means.
* ``"shooting"``: the paper's method (shoot on kappa = P/R with solve_ivp), kept as a baseline;
  it is slow and ill-conditioned near onset and raises ElasticaConvergenceError where it fails.

Supported branch: 0 <= e/L <= E_OVER_L_MAX = 0.81209, where the axial load falls to zero (see
``constants`` for why, and for the load peak that ends the rising branch).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Literal, overload

from numpy.typing import ArrayLike

from . import accurate, fast, shooting
from .constants import (
    E_OVER_L_MAX,
    E_OVER_L_PEAK,
    E_OVER_L_TIP_NORMAL,
    P_CRIT,
    P_PEAK,
)
from .errors import ElasticaConvergenceError
from .shooting import ShootingSolution
from .solution import ElasticaSolution, PostBuckling

Method = Literal["accurate", "fast", "shooting"]

SOLVERS: dict[str, Callable[[ArrayLike], PostBuckling]] = {
    "accurate": accurate.solve,
    "fast": fast.solve,
    "shooting": shooting.solve,
}


@overload
def post_buckling(
    e_over_L: ArrayLike, method: Literal["accurate", "fast"] = ...
) -> ElasticaSolution: ...
@overload
def post_buckling(e_over_L: ArrayLike, method: Literal["shooting"]) -> ShootingSolution: ...
@overload
def post_buckling(e_over_L: ArrayLike, method: str) -> PostBuckling: ...


def post_buckling(e_over_L: ArrayLike, method: str = "accurate") -> PostBuckling:
    """First-mode clamped-pinned state(s) for end shortening ratio ``e_over_L`` (any shape).

    Raises ValueError naming ``e_over_L`` if it is NaN, infinite, negative or beyond
    E_OVER_L_MAX, ValueError naming ``method`` for an unknown method, and
    ElasticaConvergenceError if the chosen solver does not converge.
    """
    try:
        solver = SOLVERS[method]
    except KeyError:
        raise ValueError(f"method must be one of {sorted(SOLVERS)}, got {method!r}") from None
    return solver(e_over_L)


__all__ = [
    "E_OVER_L_MAX",
    "E_OVER_L_PEAK",
    "E_OVER_L_TIP_NORMAL",
    "P_CRIT",
    "P_PEAK",
    "SOLVERS",
    "ElasticaConvergenceError",
    "ElasticaSolution",
    "Method",
    "PostBuckling",
    "ShootingSolution",
    "post_buckling",
]
