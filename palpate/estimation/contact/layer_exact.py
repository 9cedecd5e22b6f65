"""The exact linear-elastic contact of a rigid sphere on a layer over a rigid base.

A frictionless rigid axisymmetric indenter of profile ``f(r)`` presses a layer of thickness
``h`` (modulus E, Poisson ratio nu) bonded to, or sliding on, a rigid base. With the pressure
written through Copson's representation, ``p(r) = -(1/r) d/dr int_r^a t g(t)/sqrt(t^2 - r^2) dt``
up to a constant (so the pressure's Hankel transform is ``int_0^a g(t) cos(xi t) dt``), the
mixed boundary-value problem (Sneddon 1966; Lebedev & Ufliand 1958) becomes a Fredholm integral
equation of the second kind on the contact ``0 <= t <= a``::

    g(t) + int_0^a g(s) L(t, s) ds = (E*/pi) (delta - phi(t)),   E* = E / (1 - nu^2)
    L(t, s) = M((s - t)/h)/h + M((s + t)/h)/h,   M(x) = 1/pi int_0^inf (K(u) - 1) cos(u x) du

with K the layer's surface-compliance kernel (``estimation.contact.layer.layer_kernel``) and
``phi`` the
Abel transform of the profile: ``t^2/R`` for Hertz's paraboloid, ``t artanh(t/R)`` for a sphere
(Sneddon's; it gives his delta = a artanh(a/R) on a half-space, where K = 1). The edge of contact
has zero pressure, ``g(a) = 0``, which fixes delta for a given contact radius a, and the load is
``F = 2 pi int_0^a g dt``. On a half-space this is Hertz's and Sneddon's law exactly.

In units of h (tau = t/h, alpha = a/h, rho = R/h), by linearity ``g = E*/pi (h^2/R)(D g1 - g2)``
with ``(I + L) g1 = 1`` and ``(I + L) g2 = phi R/h^2``, so ``D = delta R/h^2 = g2(alpha) /
g1(alpha)`` and ``F R/(E* h^3) = 2 (D int g1 - int g2)``. ``L`` is smooth (K - 1 decays as
u^2 e^(-2u)), so a Gauss-Legendre Nystrom discretisation converges exponentially; ``M`` is
tabulated once per kernel by composite Gauss-Legendre quadrature and interpolated linearly,
which is what is left between 32 and 64 nodes: 1e-7 in force at a/h < 1, 3e-6 at a/h = 6
(tests).

This module is the solver: pure functions, SI-free dimensionless numbers. ``estimation.
layer_table`` turns it into the law the estimator fits. The world's finite-element code
(``sim.fem``) solves the same elasticity problem by a different method (a mixed FE on a finite
dish); they agree to 0.1 % on the paper's phantom to delta/R = 0.9 (docs/estimation.md).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .layer import layer_kernel

FloatArray = NDArray[np.float64]

KERNEL_U_MAX = 40.0
"""Upper end of the kernel's u-integral: |K - 1| < 1e-31 beyond (it decays as u^2 e^(-2u))."""
KERNEL_PANELS = 160
KERNEL_ORDER = 16
KERNEL_X_STEP = 0.005
KERNEL_X_MAX = 16.0
"""M(x) is tabulated on [0, KERNEL_X_MAX] (contact radii up to 8 h) every KERNEL_X_STEP;
linear interpolation errs by < 1e-6 there (M'' is of order 0.1)."""
NODES = 32


class LayerSolveError(ValueError):
    """The layer's contact equation has no admissible solution at the asked contact radius (an
    edge condition with no positive pressure, or a non-finite result)."""


@dataclass(frozen=True, eq=False)
class LayerKernel:
    """M(x) = 1/pi int_0^inf (K(u) - 1) cos(u x) du on a uniform grid, for one layer kind."""

    poisson: float
    bonded: bool
    step: float
    values: FloatArray

    def at(self, x: FloatArray) -> FloatArray:
        """M at ``x`` >= 0 (linear interpolation; past the table, its last value, ~0)."""
        return np.interp(x, np.arange(self.values.size) * self.step, self.values)


@functools.lru_cache(maxsize=64)
def kernel_transform(poisson: float, bonded: bool) -> LayerKernel:
    """The cosine transform M of ``layer_kernel(u, poisson, bonded) - 1`` (cached: ~50 ms). A
    frictionless base's kernel does not depend on nu, so its transform is shared."""
    nu = float(poisson) if bonded else 0.0
    g, w = np.polynomial.legendre.leggauss(KERNEL_ORDER)
    edges = np.linspace(0.0, KERNEL_U_MAX, KERNEL_PANELS + 1)
    half = 0.5 * np.diff(edges)[:, None]
    u = (0.5 * (edges[:-1] + edges[1:])[:, None] + half * g).ravel()
    weights = (half * w).ravel() * (layer_kernel(u, nu, bonded) - 1.0) / math.pi
    x = np.arange(0.0, KERNEL_X_MAX + 0.5 * KERNEL_X_STEP, KERNEL_X_STEP)
    values = np.cos(np.outer(x, u)) @ weights
    return LayerKernel(nu, bonded, KERNEL_X_STEP, np.asarray(values))


@dataclass(frozen=True)
class LayerContact:
    """Dimensionless solutions at contact radii ``alpha = a/h`` (arrays of the same shape).

    Attributes:
        alpha: a/h.
        depth: D = delta R / h^2 (for the paraboloid, chi^2 with chi = sqrt(R delta)/h).
        force: F R / (E* h^3).
    """

    alpha: FloatArray
    depth: FloatArray
    force: FloatArray


def _profile(tau: FloatArray, rho: float) -> FloatArray:
    """phi R / h^2 at tau = t/h: tau^2 for the paraboloid (rho = inf), the sphere's
    ``tau rho artanh(tau/rho)`` otherwise (rho = R/h)."""
    if math.isinf(rho):
        return np.asarray(tau * tau)
    return np.asarray(tau * rho * np.arctanh(tau / rho))


def _nystrom(
    a: FloatArray, rho: float, kernel: LayerKernel, nodes: int
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """Nodes tau, weights, g1, g2 (each (n_a, nodes)) and the depth D of the contact at each
    radius in ``a`` (already checked)."""
    g, w = np.polynomial.legendre.leggauss(nodes)
    tau = a[:, None] * (0.5 * (g + 1.0))
    wt = a[:, None] * (0.5 * w)
    diff = np.abs(tau[:, :, None] - tau[:, None, :])
    summ = tau[:, :, None] + tau[:, None, :]
    lam = kernel.at(diff) + kernel.at(summ)
    system = np.eye(nodes)[None] + lam * wt[:, None, :]
    rhs = np.stack([np.ones_like(tau), _profile(tau, rho)], axis=-1)
    sol = np.linalg.solve(system, rhs)
    g1, g2 = sol[..., 0], sol[..., 1]
    edge = kernel.at(np.abs(a[:, None] - tau)) + kernel.at(a[:, None] + tau)
    g1a = 1.0 - np.sum(edge * wt * g1, axis=1)
    g2a = _profile(a, rho) - np.sum(edge * wt * g2, axis=1)
    if not np.all(np.isfinite(g1a) & (g1a > 0.0)):
        raise LayerSolveError("the layer's contact equation has no positive edge solution")
    return tau, wt, np.asarray(g1), np.asarray(g2), np.asarray(g2a / g1a)


def _checked_radii(alpha: FloatArray, rho: float) -> FloatArray:
    a = np.atleast_1d(np.asarray(alpha, dtype=np.float64))
    top = min(rho, 0.5 * KERNEL_X_MAX)
    if not np.all(np.isfinite(a) & (a > 0.0) & (a < top)):
        raise LayerSolveError(f"contact radius a/h must be in (0, {top:.4g}), got {a.min():.4g}")
    return a


def solve_contact(
    alpha: FloatArray, rho: float, kernel: LayerKernel, nodes: int = NODES
) -> LayerContact:
    """The layer's contact at each contact radius ``alpha`` = a/h (> 0), for a sphere of radius
    ``rho`` = R/h (``math.inf``: Hertz's paraboloid). All radii are solved as one batch.

    Raises:
        LayerSolveError: alpha outside (0, min(rho, KERNEL_X_MAX/2)), or a radius with no
            admissible solution (g1(a) <= 0 or a non-finite load).
    """
    a = _checked_radii(alpha, rho)
    _, wt, g1, g2, depth = _nystrom(a, rho, kernel, nodes)
    force = 2.0 * (depth * np.sum(wt * g1, axis=1) - np.sum(wt * g2, axis=1))
    if not np.all(np.isfinite(force) & (force > 0.0)):
        raise LayerSolveError("the layer's contact load is not finite and positive")
    return LayerContact(a, np.asarray(depth), np.asarray(force))


def contact_density(
    alpha: float, rho: float, kernel: LayerKernel, nodes: int = NODES
) -> tuple[FloatArray, FloatArray, float]:
    """The contact's Copson density at radius ``alpha`` = a/h: Gauss-Legendre nodes ``tau`` of
    [0, alpha], ``g(tau) pi R / (E* h^2)`` there (the pressure's Hankel transform is
    ``int g cos(xi t) dt``), and the depth D = delta R / h^2 (``estimation.contact.finite_strain``
    builds
    the layer's interior fields from it).

    Raises:
        LayerSolveError: as :func:`solve_contact`.
    """
    a = _checked_radii(np.asarray([alpha]), rho)
    tau, _, g1, g2, depth = _nystrom(a, rho, kernel, nodes)
    return tau[0], depth[0] * g1[0] - g2[0], float(depth[0])
