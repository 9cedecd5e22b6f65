"""The neo-Hookean departure from the linear law, to second order, for a sphere on a layer.

Second-order elasticity (Rivlin; Du et al. 2022, arXiv:2209.05646, for the half-space): press a
rigid sphere a depth delta into a hyperelastic body. The energy the body stores, minimised under
the contact constraint, is ``Pi(delta) = W2[u1] + W3[u1] + C[u1] + O(delta^4 ...)``, where
``u1`` is the linear-elastic solution, ``W2`` its quadratic energy (whose derivative is the
linear law ``F1``), ``W3`` the cubic part of the material's energy evaluated on ``u1``, and
``C`` the work of the linear contact pressure on the second-order part of the constraint
(the correction ``u2`` itself enters only at fourth order, ``W2`` being stationary at ``u1``).
The force is ``F = dPi/ddelta``, so the relative departure from the linear law is::

    D(delta) = d(W3 + C)/ddelta / F1

- the material: the neo-Hookean solid of the world's scenes (Simo-Taylor,
  ``mu/2 (J^(-2/3) I1 - 3) + K/2 (J - 1)^2``), whose cubic part, with the invariants
  ``i1 = tr H``, ``i2``, ``i3 = det H`` of the displacement gradient H, is
  ``mu/2 (-2 i3 + 2 i1 i2 - 10/27 i1^3 - 2/3 i1 |H|^2) + K i1 i2`` (:func:`cubic_energy`);
- the frictionless tip: a surface point in contact lies on the sphere where it is *now*, at
  ``r + u_r``: the constraint's second-order part is ``u2_z = -r u1_r / sqrt(R^2 - r^2)``, so
  ``C = -int p1 r u1_r / sqrt(R^2 - r^2) dA``;
- the sticking tip (full stick): a point keeps the radial displacement it had when the contact
  reached it, ``u_r(r) = u1_r(r; a = r)``, so ``C`` takes that frozen value instead; the
  stick's own shear field is left out, and :func:`_sticking` bridges the two limits where that
  is right (a thin layer, a half-space). An approximation: within 0.7 % of the world's FE to
  delta/h = 0.2 on the thin layers, 0.5 % on the lung and paper layers to delta/R = 0.2
  (docs/layer-law.md), but on a sliding layer under the lung's 10 mm tip (h/R 0.16-0.25) the
  FE leaves the limits by up to 2-6 % at delta/h 0.2-0.25: the interval carries half the
  limits' spread on a bonded layer and the stick's whole effect on a sliding one
  (``estimation.jointfit.modelform``).

``u1`` comes from the exact linear layer law's contact density (``estimation.contact.layer_exact``)
and the layer's Hankel-space fields (:mod:`.fields`); nothing here uses the world's finite
elements. Against them (docs/layer-law.md, "Finite strain"): the frictionless departure within
0.2 % of the world's to delta/h = 0.2 on 1.5-3 mm layers, bonded and sliding (0.44 % at 0.3),
0.32 % on the thick ones to delta/R = 0.2.

    >>> row = departure_row(1 / 2.33, 0.45, bonded=True)     # h/R = 0.43
    >>> row.depth_ratio, row.frictionless, row.sticking      # delta/R, D, D
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import CubicSpline  # type: ignore[import-untyped,unused-ignore]

from ..layer_exact import contact_density, kernel_transform, solve_contact
from .fields import Grid, depth_nodes, gradients, pressure_transform, surface

FloatArray = NDArray[np.float64]

ROW_POINTS = 20
"""Contact radii solved a row (the departure is a smooth curve: a spline through them)."""
STRAIN_REACH = 0.45
"""Each layer row reaches delta/h = STRAIN_REACH (or the sphere's DEPTH_REACH)."""
DEPTH_REACH = 0.6
"""Deepest delta/R of a row."""


def cubic_energy(H: tuple[FloatArray, ...], nu: float) -> FloatArray:
    """The cubic part of the neo-Hookean energy density (E* = 1) at axisymmetric gradients
    ``H = (du_r/dr, du_r/dz, du_z/dr, du_z/dz, u_r/r)``."""
    hrr, hrz, hzr, hzz, htt = H
    mu = 0.5 * (1.0 - nu)
    bulk = (1.0 - nu * nu) / (3.0 * (1.0 - 2.0 * nu))
    i1 = hrr + hzz + htt
    minor = hrr * hzz - hrz * hzr
    i2 = minor + (hrr + hzz) * htt
    i3 = minor * htt
    norm2 = hrr * hrr + hrz * hrz + hzr * hzr + hzz * hzz + htt * htt
    iso = -2.0 * i3 + 2.0 * i1 * i2 - 10.0 / 27.0 * i1**3 - 2.0 / 3.0 * i1 * norm2
    return np.asarray(0.5 * mu * iso + bulk * i1 * i2)


@dataclass(frozen=True, eq=False)
class _Point:
    """One contact radius (``radius`` = a/R) in units of a and E*: the linear contact's pressure
    transform and gradients (frictionless), the surface fields the contact terms need, and in
    units of R: depth delta/R and load F1/(E* R^2)."""

    radius: float
    thickness: float  # h/a (inf: half-space)
    depth: float
    load: float
    transform: FloatArray
    strain: tuple[FloatArray, ...]
    depth_weights: FloatArray
    pressure: FloatArray  # at grid.r_in
    radial: FloatArray  # u_r at grid.r_in
    edge: float  # u_r at the contact's edge
    slip: FloatArray  # the same pressure's u_r on a half-space, at grid.r_in
    slip_edge: float  # and at the edge

    def energy(self, strain: tuple[FloatArray, ...], nu: float) -> float:
        """The cubic energy of the field ``strain`` in units of E* R^3."""
        grid = Grid.default()
        density = cubic_energy(strain, nu)
        area = (grid.w_r * 2.0 * math.pi * grid.r)[:, None] * self.depth_weights[None, :]
        return float(np.sum(density * area)) * self.radius**3

    def contact(self, radial: FloatArray) -> float:
        """``-int p r u_r / sqrt(R^2 - r^2) dA`` for the surface's ``radial`` displacement at
        grid.r_in (units of a), in units of E* R^3."""
        grid = Grid.default()
        sphere = 1.0 / self.radius
        lever = grid.r_in / np.sqrt(sphere * sphere - grid.r_in * grid.r_in)
        work = np.sum(grid.w_in * 2.0 * math.pi * grid.r_in * self.pressure * lever * radial)
        return -float(work) * self.radius**3


def _density(radius: float, thickness: float, nu: float, bonded: bool) -> tuple[FloatArray, ...]:
    """Nodes and Copson density of the linear contact in units of a and E* (radius = a/R,
    thickness = h/R, inf: Sneddon's half-space), with delta/R and F1/(E* R^2)."""
    if not math.isfinite(thickness):
        g, w = np.polynomial.legendre.leggauss(32)
        tau = 0.5 * (g + 1.0)
        depth = math.atanh(radius)  # delta/a: Sneddon's a artanh(a/R)
        dens = (depth - tau * np.arctanh(tau * radius)) / math.pi
    else:
        alpha, rho = radius / thickness, 1.0 / thickness
        t, dens_h, big_d = contact_density(alpha, rho, kernel_transform(nu, bonded))
        tau, dens = t / alpha, dens_h / (math.pi * rho * alpha)
        g, w = np.polynomial.legendre.leggauss(tau.size)
        depth = big_d / rho / alpha  # delta/a
    load = 2.0 * math.pi * float(np.sum(0.5 * w * dens)) * radius * radius
    return tau, dens, np.asarray([depth * radius, load])


def _point(radius: float, thickness: float, nu: float, bonded: bool) -> _Point:
    grid = Grid.default()
    tau, dens, (depth, load) = _density(radius, thickness, nu, bonded)
    P = pressure_transform(grid.xi, tau, dens)
    h = thickness / radius  # in units of a
    z, wz = depth_nodes(h)
    strain = gradients(grid, P, z, nu, bonded, h)
    ur, p, edge = surface(grid, P, nu, bonded, h)
    slip, _, slip_edge = surface(grid, P, nu, bonded, math.inf)
    return _Point(radius, h, depth, load, P, strain, wz, p, ur, edge, slip, slip_edge)


def _sticking(points: list[_Point], nu: float) -> tuple[FloatArray, FloatArray]:
    """The sticking tip's cubic energy plus contact term at each point (units of E* R^3), and
    half the spread between its two limits.

    Full stick freezes each surface point's radial displacement at the value it had when the
    contact reached it, the edge's then. The stick's own shear field is left out of ``u1``,
    and with it two limits bracket what the freeze does to the energy: the whole radial
    displacement frozen (right on a thin layer, whose confined flow outwards the stick holds;
    within 0.3 % of the FE on the 1.5 mm bonded layer) or only the layer's part of it, the
    half-space's inward slip of the same pressure (order 1 - 2 nu) left to follow the load
    (right on a half-space, where the FE's sticking and frictionless departures agree, as
    Spence's linear stick changes Hertz's load only at order (1 - 2 nu)^2). The estimate
    weighs the slip's freeze by the layer's share of the edge's radial displacement."""
    grid = Grid.default()
    radii = np.array([q.radius for q in points])
    layer = np.array([(q.edge - q.slip_edge) * q.radius for q in points])
    slip = np.array([q.slip_edge * q.radius for q in points])
    blend, spread = [], []
    for q in points:
        r = grid.r_in * q.radius
        fixed = _frozen(r, radii, layer) / q.radius
        frozen_slip = _frozen(r, radii, slip) / q.radius
        share = abs(q.edge - q.slip_edge) / (abs(q.edge - q.slip_edge) + abs(q.slip_edge))
        cubic = q.energy(q.strain, nu)
        held = fixed + share * frozen_slip + (1.0 - share) * q.slip
        blend.append(cubic + q.contact(held))
        spread.append(0.5 * (q.contact(fixed + frozen_slip) - q.contact(fixed + q.slip)))
    return np.asarray(blend), np.asarray(spread)


def _frozen(r: FloatArray, radii: FloatArray, edges: FloatArray) -> FloatArray:
    """The frozen radial displacement at surface radii ``r`` (units of R) from the edge's at
    each earlier contact radius (~r^2 below the first, as on a half-space)."""
    first = edges[0] * (r / radii[0]) ** 2
    return np.asarray(np.where(r < radii[0], first, np.interp(r, radii, edges)))


@dataclass(frozen=True)
class DepartureRow:
    """The departure ``F_neo-Hookean / F_linear - 1`` at depths ``depth_ratio`` (delta/R) for
    one layer (``thickness_ratio`` = h/R, inf: a half-space), Poisson ratio and base, for a
    frictionless and a sticking tip, and half the spread of the sticking tip's two limits
    (``stick_spread``, >= 0)."""

    thickness_ratio: float
    poisson: float
    bonded: bool
    depth_ratio: FloatArray
    frictionless: FloatArray
    sticking: FloatArray
    stick_spread: FloatArray


def _radii(thickness: float, nu: float, bonded: bool) -> FloatArray:
    """ROW_POINTS contact radii a/R reaching delta/h = STRAIN_REACH or delta/R = DEPTH_REACH."""
    top_depth = DEPTH_REACH
    if not math.isfinite(thickness):
        trial = np.linspace(0.01, 0.95, 400)
        depth = trial * np.arctanh(trial)
    else:
        top_depth = min(DEPTH_REACH, STRAIN_REACH * thickness)
        alpha = np.linspace(0.01, 0.95, 400) / thickness
        alpha = alpha[alpha < min(1.0 / thickness, 7.5)]
        c = solve_contact(alpha, 1.0 / thickness, kernel_transform(nu, bonded))
        trial, depth = alpha * thickness, c.depth * thickness * thickness
    top = float(np.interp(top_depth, depth, trial))
    return np.linspace(top / ROW_POINTS, top, ROW_POINTS)


def departure_row(thickness_ratio: float, poisson: float, bonded: bool) -> DepartureRow:
    """The departure along one row (~1.2 s). ``thickness_ratio`` = h/R (``math.inf``: a
    half-space); ``poisson`` < 0.5 (the table's last row is 0.499)."""
    if not 0.0 <= poisson < 0.5:
        raise ValueError(f"poisson must be in [0, 0.5), got {poisson!r}")
    points = [
        _point(float(a), thickness_ratio, poisson, bonded)
        for a in _radii(thickness_ratio, poisson, bonded)
    ]
    depth = np.array([q.depth for q in points])
    load = np.array([q.load for q in points])
    slide = np.array([q.energy(q.strain, poisson) + q.contact(q.radial) for q in points])
    stick, spread = _sticking(points, poisson)
    d0 = np.concatenate([[0.0], depth])

    def slope(energy: FloatArray) -> FloatArray:
        return np.asarray(CubicSpline(d0, np.concatenate([[0.0], energy])).derivative()(depth))

    return DepartureRow(
        thickness_ratio,
        poisson,
        bonded,
        depth,
        slope(slide) / load,
        slope(stick) / load,
        np.abs(slope(spread) / load),
    )
