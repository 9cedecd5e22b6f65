"""Vectorised surrogate of the first mode: Chebyshev series in e/L built once from ``accurate``.

What is interpolated, and why it is smooth: along the branch k**2 and p are analytic functions of
e/L (both are even in k and e/L ~ 0.953 k**2 at onset), and r, the tip angle and k itself are odd
in k, i.e. sqrt(e/L) times analytic functions. So we interpolate, on [0, E_OVER_L_MAX],

    p,  r / sqrt(e/L),  tip_angle / sqrt(e/L),  k / sqrt(e/L),  t,  u0,

and multiply the odd ones back by sqrt(e/L): relative accuracy then holds down to e/L = 0 (no
log-spacing or onset special case is needed). With 64 Chebyshev nodes the coefficients fall to
1e-15 of the leading one (measured), so a series chopped at ``chop`` = 1e-12 keeps about 45
terms. Grating means and shapes use the exact closed-form shape functions (``solution``) with the
interpolated (k, t, u0): the mean over [s0, s1] is (theta(s1) - theta(s0)) / (s1 - s0), two
Jacobi sn evaluations per interval, no quadrature.

Cost (2-core machine): building 64 accurate states takes about 0.15 s, so the surrogate is
cached in memory only (a disk cache would cost more in invalidation logic than it saves);
a 10,000-state batch with three grating means takes about 2-3 us per state.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import accurate
from .constants import E_OVER_L_MAX
from .errors import checked_e_over_L
from .solution import ElasticaSolution

FloatArray = NDArray[np.float64]

NODES = 64
CHOP = 1e-12
# Rows of the coefficient table.
P, R, TIP, K, T, U0 = range(6)


@dataclass(frozen=True)
class Surrogate:
    """Chebyshev coefficients (n_terms, 6) in x = 2 (e/L) / E_OVER_L_MAX - 1, columns P..U0."""

    coef: FloatArray
    dp_coef: FloatArray  # coefficients of dp/d(e/L), (n_terms - 1,)

    def evaluate(self, e_over_L: FloatArray, columns: tuple[int, ...]) -> FloatArray:
        """Series ``columns`` at ``e_over_L`` (any shape) -> shape (len(columns),) + e.shape."""
        return clenshaw(self.coef[:, list(columns)], 2.0 * e_over_L / E_OVER_L_MAX - 1.0)

    def dp(self, e_over_L: FloatArray) -> FloatArray:
        """dp / d(e/L) at ``e_over_L`` (any shape)."""
        return np.asarray(
            clenshaw(self.dp_coef[:, None], 2.0 * e_over_L / E_OVER_L_MAX - 1.0)[0], dtype=float
        )


SMALL_BATCH = 2048


def clenshaw(coef: FloatArray, x: FloatArray) -> FloatArray:
    """Sum of coef[j, f] T_j(x) for each column f: shape (n_functions,) + x.shape.

    Small batches use T_j(x) = cos(j arccos x) and one matrix product (3 numpy calls instead of
    3 per term, which dominate a single query); large ones use Clenshaw's recurrence, which needs
    no (N, n_terms) temporary. Both err by about n_terms**2 * 1e-16.
    """
    if x.size <= SMALL_BATCH:
        degrees = np.arange(coef.shape[0])
        basis = np.cos(np.arccos(np.clip(x, -1.0, 1.0))[..., None] * degrees)
        return np.asarray(np.moveaxis(basis @ coef, -1, 0))
    shape = (coef.shape[1],) + (1,) * x.ndim
    b1 = np.zeros((coef.shape[1], *x.shape))
    b2 = np.zeros_like(b1)
    two_x = 2.0 * x
    for j in range(coef.shape[0] - 1, 0, -1):
        b1, b2 = coef[j].reshape(shape) + two_x * b1 - b2, b1
    return np.asarray(coef[0].reshape(shape) + x * b1 - b2)


@lru_cache(maxsize=4)
def surrogate(nodes: int = NODES, chop: float = CHOP) -> Surrogate:
    """Build (once per argument pair, then cached) the Chebyshev surrogate from ``accurate``."""
    x = np.cos(np.pi * (np.arange(nodes) + 0.5) / nodes)
    e = 0.5 * (x + 1.0) * E_OVER_L_MAX
    sol = accurate.solve(e)
    root = np.sqrt(e)
    values = np.stack(
        [sol.p, sol.r / root, sol.tip_angle / root, sol.modulus / root, sol.wavenumber, sol.u0],
        axis=1,
    )
    coef = np.polynomial.chebyshev.chebfit(x, values, nodes - 1)
    scale = np.abs(coef).max(axis=0)
    significant = np.nonzero(np.any(np.abs(coef) > chop * scale, axis=1))[0]
    n_terms = int(significant[-1]) + 1
    kept: FloatArray = np.ascontiguousarray(coef[:n_terms], dtype=np.float64)
    dp_coef = np.polynomial.chebyshev.chebder(kept[:, P]) * (2.0 / E_OVER_L_MAX)
    return Surrogate(coef=kept, dp_coef=np.asarray(dp_coef, dtype=np.float64))


def load(e_over_L: ArrayLike) -> FloatArray:
    """p(e/L) only (the simulator's hot path): one Chebyshev series, no elliptic functions."""
    e = checked_e_over_L(e_over_L, E_OVER_L_MAX)
    return np.asarray(surrogate().evaluate(e, (P,))[0], dtype=np.float64)


def load_slope(e_over_L: ArrayLike) -> FloatArray:
    """dp / d(e/L) (for Newton steps on the extensible beam)."""
    e = checked_e_over_L(e_over_L, E_OVER_L_MAX)
    return surrogate().dp(e)


def reaction(e_over_L: ArrayLike) -> FloatArray:
    """r(e/L) only: one series times sqrt(e/L)."""
    e = checked_e_over_L(e_over_L, E_OVER_L_MAX)
    return np.asarray(surrogate().evaluate(e, (R,))[0] * np.sqrt(e))


def solve(e_over_L: ArrayLike) -> ElasticaSolution:
    """First-mode states for ``e_over_L`` (any shape), vectorised; relative error <= 1e-10."""
    e = checked_e_over_L(e_over_L, E_OVER_L_MAX)
    p, r, tip, k, t, u0 = surrogate().evaluate(e, (P, R, TIP, K, T, U0))
    root = np.sqrt(e)
    return ElasticaSolution(
        e_over_L=e,
        p=p,
        r=r * root,
        tip_angle=tip * root,
        modulus=k * root,
        wavenumber=t,
        u0=u0,
        method="fast",
    )
