"""Axial load and end shortening of the sensor beam at every sample of a record, from its strains.

Each grating reads its mean bending strain plus the uniform axial strain -P/EA (Eq. 3, Eq. 12).
``estimation.fits.strain_fit.fit_strains`` ties P to the bending through the perfect elastica (P >=
P_cr
once bent).
A real beam is not straight: its bending grows smoothly while P is still below P_cr (the
imperfection the paper saw at small post-buckling displacement), so the load read that way is
too high until well past the onset. Here P is a free unknown beside the bending amplitude::

    y_g = B_g(z) - P / EA,        z = sign * sqrt(e_g / L),  g = 1..G (G >= 3 for a residual)

with B_g the elastica's grating-mean bending strain at e_g/L = z^2 (an odd function of the
signed z: the two mirror images). Near the onset B(z) = z m1 + O(z^2): the same model covers the
straight beam (z ~ 0, P from the axial strain alone), the imperfect beam's growing bow and the
buckled states. P enters linearly, so it is concentrated out and z solves a one-dimensional
Gauss-Newton problem, vectorised over samples (started from the linear onset-mode fit). The end
shortening is e = P L / EA + z^2 L.

Shapes: N samples, G gratings. Arc positions are metres from the clamp (s = L - distance from
the tip), one row per sample because the exposed length L grows on the robot. Arc inside the
tube (s < 0) is straight. Standard deviations come from the linearised 2-parameter fit at each
sample with the strain noise ``sigma_strain`` (the FBG noise over k'_eps).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .elastica import fast
from .elastica.constants import E_OVER_L_MAX

FloatArray = NDArray[np.float64]

ONSET_STEP = 1e-4  # z at which the onset mode shape m1 = B(z)/z is taken
DIFF_STEP = 1e-6  # central-difference step in z for dB/dz
GN_TOL = 1e-12  # on z
GN_MAXITER = 25
Z_MAX = math.sqrt(E_OVER_L_MAX) * (1.0 - 1e-9)


@dataclass(frozen=True)
class BeamStates:
    """The beam along a record; every array has shape (N,).

    Attributes:
        P: axial load (N), compression positive.
        e: total end shortening (m), P L / EA + e_g.
        z: signed sqrt(e_g / L) (the bending amplitude; its sign is the buckling direction).
        sigma_P, sigma_e: standard deviations of P (N) and e (m) from the strain noise.
        residual: rms over gratings of measured minus fitted strain.
        converged: the Gauss-Newton iteration met its tolerance at that sample.
    """

    P: FloatArray
    e: FloatArray
    z: FloatArray
    sigma_P: FloatArray  # noqa: N815 - the paper's P
    sigma_e: FloatArray
    residual: FloatArray
    converged: NDArray[np.bool_]


@dataclass(frozen=True)
class _Geometry:
    a: FloatArray  # (N, G) grating starts, fractions of L, clipped to [0, 1]
    b: FloatArray  # (N, G) grating ends, fractions of L, clipped
    weight: FloatArray  # (N, G) exposed part of each grating / its length
    scale: FloatArray  # (N, 1) fiber_offset / L


def _geometry(intervals: FloatArray, lengths: FloatArray, fiber_offset: float) -> _Geometry:
    L = lengths[:, None]
    s0, s1 = intervals[..., 0] / L, intervals[..., 1] / L
    a, b = np.clip(s0, 0.0, 1.0), np.clip(s1, 0.0, 1.0)
    return _Geometry(a, np.maximum(b, a), (b - a) / (s1 - s0), fiber_offset / L)


def _bending(z: FloatArray, geo: _Geometry) -> FloatArray:
    """B(z): (N, G) grating-mean bending strains at signed amplitudes z (N,)."""
    mag = np.minimum(np.abs(z), Z_MAX)
    curvature = fast.solve((mag * mag)[:, None]).mean_curvature(geo.a, geo.b)
    return np.asarray(np.sign(z)[:, None] * geo.scale * geo.weight * curvature)


def _centred(x: FloatArray) -> FloatArray:
    return np.asarray(x - x.mean(axis=-1, keepdims=True))


def onset_mode(intervals: ArrayLike, length: float, fiber_offset: float) -> FloatArray:
    """m1 (G,): the grating-mean bending strains per unit amplitude z near the onset, the shape
    an imperfect beam's bow takes long before it buckles. ``intervals`` (G, 2) as in
    :func:`infer_states`."""
    arcs = np.asarray(intervals, dtype=np.float64)[None, :, :]
    geo = _geometry(arcs, np.array([float(length)]), fiber_offset)
    return np.asarray(_bending(np.array([ONSET_STEP]), geo)[0] / ONSET_STEP)


def axial_strain(strains: ArrayLike, mode: ArrayLike) -> float:
    """P/EA (compression positive) from one sample's grating strains (G,): the uniform part
    left once the bending along ``mode`` (see :func:`onset_mode`) is taken out by least squares.
    Cheap enough for a control tick; :func:`infer_states` is the full, non-linear version."""
    y = np.asarray(strains, dtype=np.float64)
    m = np.asarray(mode, dtype=np.float64)
    mc = m - m.mean()
    z = float(mc @ (y - y.mean())) / float(mc @ mc)
    return float(np.mean(z * m - y))


def infer_states(
    strains: ArrayLike,
    intervals: ArrayLike,
    lengths: ArrayLike,
    EA: float,
    fiber_offset: float,
    sigma_strain: float,
    *,
    tol: float = GN_TOL,
    maxiter: int = GN_MAXITER,
) -> BeamStates:
    """Axial load and end shortening at each sample (see the module docstring).

    Args:
        strains: (N, G) grating-mean total strains (bending plus -P/EA), G >= 3.
        intervals: (N, G, 2) or (G, 2) grating arcs (s0, s1), metres from the clamp.
        lengths: (N,) or scalar exposed length L (m).
        EA: axial rigidity (N); fiber_offset: dy_fbg (m), != 0.
        sigma_strain: strain noise per grating (> 0), for the standard deviations.
        tol, maxiter: Gauss-Newton tolerance on z and iteration limit.

    Raises:
        ValueError: shapes, non-finite values, G < 3 or non-positive parameters.
    """
    y, arcs, L = _checked(strains, intervals, lengths)
    if not (math.isfinite(EA) and EA > 0):
        raise ValueError(f"EA must be > 0 N, got {EA!r}")
    if not (math.isfinite(fiber_offset) and fiber_offset != 0):
        raise ValueError(f"fiber_offset must be finite and != 0 m, got {fiber_offset!r}")
    if not (math.isfinite(sigma_strain) and sigma_strain > 0):
        raise ValueError(f"sigma_strain must be > 0, got {sigma_strain!r}")
    geo = _geometry(arcs, L, fiber_offset)
    z, converged = _gauss_newton(y, geo, tol, maxiter)
    bend = _bending(z, geo)
    axial = np.mean(bend - y, axis=1)  # P / EA
    fit = bend - axial[:, None]
    residual = np.sqrt(np.mean((y - fit) ** 2, axis=1))
    var_z, var_a, cov_za = _covariance(z, geo, sigma_strain)
    P = EA * axial
    e = axial * L + z * z * L
    de_dz = 2.0 * z * L
    var_e = (L**2) * var_a + de_dz**2 * var_z + 2.0 * L * de_dz * cov_za
    return BeamStates(
        P=np.asarray(P),
        e=np.asarray(e),
        z=np.asarray(z),
        sigma_P=np.asarray(EA * np.sqrt(var_a)),
        sigma_e=np.asarray(np.sqrt(np.maximum(var_e, 0.0))),
        residual=np.asarray(residual),
        converged=np.asarray(converged),
    )


def _checked(
    strains: ArrayLike, intervals: ArrayLike, lengths: ArrayLike
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Strains (N, G), arcs (N, G, 2) and lengths (N,) as float arrays (arcs and lengths
    broadcast per sample); ValueError for a bad shape, a non-finite value or bad arcs."""
    y = np.asarray(strains, dtype=np.float64)
    if y.ndim != 2 or y.shape[1] < 3 or y.shape[0] == 0:
        raise ValueError(f"strains must have shape (N, G) with N >= 1, G >= 3; got {y.shape}")
    n, g_count = y.shape
    L = np.broadcast_to(np.asarray(lengths, dtype=np.float64), (n,))
    arcs = np.broadcast_to(np.asarray(intervals, dtype=np.float64), (n, g_count, 2))
    for name, arr in (("strains", y), ("lengths", L), ("intervals", arcs)):
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"{name} must be finite")
    if np.any(L <= 0):
        raise ValueError("lengths must be > 0 m")
    if np.any(arcs[..., 1] <= arcs[..., 0]) or np.any(arcs[..., 1] > L[:, None] * (1 + 1e-12)):
        raise ValueError("intervals: each grating needs s0 < s1 <= L")
    return y, arcs, L


def _gauss_newton(
    y: FloatArray, geo: _Geometry, tol: float, maxiter: int
) -> tuple[FloatArray, NDArray[np.bool_]]:
    """The amplitudes z (N,) with P concentrated out (all strains centred over the gratings),
    started from the linear onset-mode fit, and per sample whether the step met ``tol``."""
    n = y.shape[0]
    yc = _centred(y)
    m1 = _centred(_bending(np.full(n, ONSET_STEP), geo) / ONSET_STEP)
    z = np.clip(np.sum(m1 * yc, axis=1) / np.sum(m1 * m1, axis=1), -Z_MAX, Z_MAX)
    converged = np.zeros(n, dtype=bool)
    for _ in range(maxiter):
        jac = _centred(_bending(z + DIFF_STEP, geo) - _bending(z - DIFF_STEP, geo)) / (
            2 * DIFF_STEP
        )
        r = yc - _centred(_bending(z, geo))
        step = np.sum(jac * r, axis=1) / np.sum(jac * jac, axis=1)
        z = np.clip(z + step, -Z_MAX, Z_MAX)
        converged = np.abs(step) <= tol
        if np.all(converged):
            break
    return z, converged


def _covariance(
    z: FloatArray, geo: _Geometry, sigma_strain: float
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Linearised (var z, var P/EA, cov) per sample (N,) of the 2-parameter fit y = B(z) - P/EA
    with white strain noise ``sigma_strain``: the inverse of the (2, 2) normal matrix of the
    columns dB/dz (central difference) and -1."""
    jac = (_bending(z + DIFF_STEP, geo) - _bending(z - DIFF_STEP, geo)) / (2 * DIFF_STEP)
    g_count = jac.shape[1]
    s_jj = np.sum(jac * jac, axis=1)
    s_j1 = -np.sum(jac, axis=1)
    det = s_jj * g_count - s_j1**2
    var_z = sigma_strain**2 * g_count / det
    var_a = sigma_strain**2 * s_jj / det
    cov_za = -(sigma_strain**2) * s_j1 / det
    return var_z, var_a, cov_za
