"""The linear-elastic fields inside a layer pressed by an axisymmetric surface pressure.

A layer of thickness ``h`` (shear modulus mu, Poisson ratio nu) on a rigid base, bonded
(``u = 0`` at ``z = h``) or sliding (``u_z = 0``, ``sigma_rz = 0``), carries a normal pressure
``p(r)`` on its free surface ``z = 0`` (z into the layer). In Hankel space (Sneddon 1951;
Burmister 1945), with ``u_r = int xi U(xi, z) J1(xi r) dxi``, ``u_z = int xi W(xi, z) J0(xi r)
dxi`` and ``P(xi) = int p(r) r J0(xi r) dr``, Navier's equations reduce for each xi to four
modes in ``s = xi z`` (kappa = 3 - 4 nu)::

    (U, W) = (1, 1) e^-s,  (s, kappa + s) e^-s,  (1, -1) e^s,  (s, kappa - s) e^s

whose four coefficients the two surface conditions (``sigma_zz = -p``, ``sigma_rz = 0``) and
the two base conditions fix. The growing modes are carried as ``e^(s - xi h)`` so that a thick
layer (xi h up to ~10^4) stays finite; a half-space is a layer with ``h = inf``.

Everything here is in units of the contact radius ``a`` (lengths) and of ``E* = E/(1 - nu^2)``
(stresses), and is pure numpy: the module gives the five displacement-gradient components of
the axisymmetric field on a grid of (r, z) (:func:`gradients`), the surface's radial
displacement and pressure (:func:`surface`), for a pressure given by its Copson density ``g``
(``P(xi) = int_0^1 g(t) cos(xi t) dt``, :func:`pressure_transform`), the form in which the exact
layer law (``estimation.contact.layer_exact``) solves the contact.

    >>> grid = Grid.default()
    >>> P = pressure_transform(grid.xi, tau, g)          # tau, g: the contact's density
    >>> H = gradients(grid, P, nu=0.45, bonded=True, thickness=1.6)   # h = 1.6 a
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.special import j0, j1, spherical_jn  # type: ignore[import-untyped,unused-ignore]

FloatArray = NDArray[np.float64]

XI_MAX = 400.0
"""Largest wavenumber (1/a): the fields' energy converges to 1e-3 by here (1000 and 2000 agree
to 2e-5 on the 1.5 mm bonded layer)."""
XI_STEP = 0.05
"""Midpoint step of the xi quadrature: resolves J(xi r) to r = 12 a (12 points a period)."""
R_MAX = 12.0
"""Outer radius of the r grid (a): a layer's fields decay within a few h beyond the contact,
a half-space's as r^-2 (the cubic energy as r^-6)."""
Z_MAX = 12.0
"""Deepest z of the grid in a half-space or a thick layer (a)."""
INNER_POINTS = 24
OUTER_POINTS = 96
DEPTH_POINTS = 28


@dataclass(frozen=True, eq=False)
class Grid:
    """The quadrature: wavenumbers ``xi`` (midpoint rule, step ``dxi``), radii inside the contact
    ``r_in`` (Gauss-Legendre on [0, 1], weights ``w_in``) and outside it ``r_out`` (Gauss on
    [1, R_MAX], clustered at the edge as 1 + (R_MAX - 1) q^2), and the Bessel kernels of the five
    gradient components on all radii (``kernels``, each (n_r, n_xi))."""

    xi: FloatArray
    dxi: float
    r: FloatArray
    w_r: FloatArray
    r_in: FloatArray
    w_in: FloatArray
    kernels: tuple[FloatArray, ...]
    surface_kernels: tuple[FloatArray, FloatArray]
    edge_kernel: FloatArray

    @classmethod
    @functools.cache
    def default(cls) -> Grid:
        """The grid every row of the table uses (built once a process, ~0.5 s)."""
        xi = np.arange(0.5 * XI_STEP, XI_MAX, XI_STEP)
        g, w = np.polynomial.legendre.leggauss(INNER_POINTS)
        r_in, w_in = 0.5 * (g + 1.0), 0.5 * w
        g, w = np.polynomial.legendre.leggauss(OUTER_POINTS)
        q = 0.5 * (g + 1.0)
        r_out = 1.0 + (R_MAX - 1.0) * q * q
        w_out = (R_MAX - 1.0) * q * w
        r = np.concatenate([r_in, r_out])
        x = np.outer(r, xi)
        b0, b1 = j0(x), j1(x)
        b1x = b1 / x
        xi2 = xi * xi
        kernels = ((b0 - b1x) * xi2, b1 * xi, -b1 * xi2, b0 * xi, b1x * xi2)
        x_in = np.outer(r_in, xi)
        surface = (j1(x_in) * xi, j0(x_in) * xi)
        w_r = np.concatenate([w_in, w_out])
        return cls(xi, XI_STEP, r, w_r, r_in, w_in, kernels, surface, j1(xi) * xi)


def pressure_transform(xi: FloatArray, tau: FloatArray, g: FloatArray) -> FloatArray:
    """``P(xi) = int_0^1 g(t) cos(xi t) dt`` for a density ``g`` known at Gauss-Legendre nodes
    ``tau`` of [0, 1]: g's Legendre series, each term transformed exactly
    (``int_-1^1 P_n(x) e^(i w x) dx = 2 i^n j_n(w)``)."""
    coef = np.polynomial.legendre.legfit(2.0 * tau - 1.0, g, tau.size - 1)
    w = 0.5 * xi
    total = np.zeros(xi.size, dtype=np.complex128)
    for n, c in enumerate(coef):
        total += c * 2.0 * (1j**n) * spherical_jn(n, w)
    return np.asarray(0.5 * np.real(np.exp(1j * w) * total))


def _coefficients(xi: FloatArray, nu: float, bonded: bool, thickness: float) -> FloatArray:
    """The four mode coefficients (n_xi, 4) for a unit surface pressure transform, mu = 1."""
    kap = 3.0 - 4.0 * nu
    big = xi * thickness
    one, zero = np.ones_like(xi), np.zeros_like(xi)
    ep = np.exp(-big) if math.isfinite(thickness) else zero  # growing modes at s = 0, x e^(-xi h)
    # sigma_zz / (xi mu) times (1 - 2 nu), finite at nu = 0.5: 2 nu (U + W') + 2 (1 - 2 nu) W'
    top_u = np.stack([one, zero, ep, zero])
    top_w = np.stack([one, kap * one, -ep, kap * ep])
    top_us = np.stack([-one, one, ep, ep])
    top_ws = np.stack([-one, (1.0 - kap) * one, -ep, (kap - 1.0) * ep])
    rows = [2.0 * nu * (top_u + top_ws) + 2.0 * (1.0 - 2.0 * nu) * top_ws, top_us - top_w]
    if not math.isfinite(thickness):  # a half-space: no growing modes
        rows += [np.stack([zero, zero, one, zero]), np.stack([zero, zero, zero, one])]
    else:
        em = np.exp(-big)
        bot_u = np.stack([em, big * em, one, big])
        bot_w = np.stack([em, (kap + big) * em, -one, kap - big])
        bot_us = np.stack([-em, (1.0 - big) * em, one, 1.0 + big])
        rows += [bot_u, bot_w] if bonded else [bot_w, bot_us - bot_w]
    system = np.moveaxis(np.stack(rows, 0), -1, 0)
    rhs = np.zeros((xi.size, 4, 1))
    rhs[:, 0, 0] = -(1.0 - 2.0 * nu) / xi
    return np.asarray(np.linalg.solve(system, rhs)[..., 0])


def modes(
    xi: FloatArray, z: FloatArray, nu: float, bonded: bool, thickness: float
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """U, W, dU/dz, dW/dz (each (n_z, n_xi)) at depths ``z`` for a unit pressure transform and
    mu = 1; ``thickness`` = h (``math.inf``: a half-space)."""
    c = _coefficients(xi, nu, bonded, thickness)
    h = thickness if math.isfinite(thickness) else 1e300
    a, b, cg, d = (c[:, i] for i in range(4))
    kap = 3.0 - 4.0 * nu
    s = np.outer(z, xi)
    em = np.exp(-s)
    ep = np.exp(np.minimum(s - xi * h, 0.0))
    u = (a + b * s) * em + (cg + d * s) * ep
    w = (a + b * (kap + s)) * em + (-cg + d * (kap - s)) * ep
    us = (-a + b * (1.0 - s)) * em + (cg + d * (1.0 + s)) * ep
    ws = (-a + b * (1.0 - kap - s)) * em + (-cg + d * (kap - 1.0 - s)) * ep
    return u, w, us * xi, ws * xi


def depth_nodes(thickness: float) -> tuple[FloatArray, FloatArray]:
    """Gauss-Legendre depths and weights over [0, min(h, Z_MAX)], clustered at the surface."""
    g, w = np.polynomial.legendre.leggauss(DEPTH_POINTS)
    top = min(thickness, Z_MAX)
    q = 0.5 * (g + 1.0)
    return top * q * q, top * q * w


def gradients(
    grid: Grid, P: FloatArray, z: FloatArray, nu: float, bonded: bool, thickness: float
) -> tuple[FloatArray, ...]:
    """The five gradient components ``(du_r/dr, du_r/dz, du_z/dr, du_z/dz, u_r/r)`` on
    ``grid.r`` x ``z`` (each (n_r, n_z)) for the pressure transform ``P`` (E* = 1 units)."""
    mu = 0.5 * (1.0 - nu)  # E = 1 - nu^2 when E* = 1
    u, w, uz, wz = modes(grid.xi, z, nu, bonded, thickness)
    amp = P * grid.dxi / mu
    k_rr, k_rz, k_zr, k_zz, k_tt = grid.kernels
    return (
        k_rr @ (u * amp).T,
        k_rz @ (uz * amp).T,
        k_zr @ (w * amp).T,
        k_zz @ (wz * amp).T,
        k_tt @ (u * amp).T,
    )


def surface(
    grid: Grid, P: FloatArray, nu: float, bonded: bool, thickness: float
) -> tuple[FloatArray, FloatArray, float]:
    """The surface's radial displacement and pressure at ``grid.r_in`` (inside the contact), and
    the radial displacement at the contact's edge (r = 1)."""
    mu = 0.5 * (1.0 - nu)
    u0 = modes(grid.xi, np.zeros(1), nu, bonded, thickness)[0][0]
    amp = u0 * P * grid.dxi / mu
    ur = grid.surface_kernels[0] @ amp
    p = grid.surface_kernels[1] @ (P * grid.dxi)
    return np.asarray(ur), np.asarray(p), float(grid.edge_kernel @ amp)
