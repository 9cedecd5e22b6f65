"""Oblique contact: the tissue as the sensor axis sees it when it meets the surface at an angle.

With a misalignment psi between the sensor axis t and the inward normal -n at the contact, the
tip sphere indents the tissue along the normal (depth ``delta_n``) and moves tangentially along
the surface (``s``, along m, the surface direction t leans toward: t = -cos psi n + sin psi m).
The beam is stiff along its axis (EA/L ~ 2e5 N/m) and very soft across it (3 EI/L^3 ~ 5 N/m,
against the tissue's tangential stiffness of hundreds of N/m), so before buckling the tissue's
resultant on the tip must lie along the axis: the tangential traction is T = F_n tan psi.

* **Stick** (tan psi <= mu, Coulomb with the sample's friction mu): the tissue carries T by its
  tangential stiffness. For a rigid sphere on an elastic solid Mindlin's tangential stiffness is
  ``k_t = rho k_n`` with ``rho = 2 (1 - nu) / (2 - nu)`` at every depth, and under loading
  along a fixed direction below the friction limit no micro-slip occurs (Mindlin and
  Deresiewicz), so ``s = delta_n tan psi / rho``. The tip's travel along the axis and the axial
  load are then::

      a = delta_n (cos psi + sin psi tan psi / rho),      P = F_n(delta_n) / cos psi

  The tip is held laterally (a pin, as the aligned model assumes); it sits off the clamp's axis
  by ``delta_n sin psi (1/rho - 1)`` (< 0.2 delta_n at 25 deg), whose pre-bend is not modelled.
* **Slip** (tan psi > mu): T saturates at mu F_n and the resultant leans gamma = psi - atan(mu)
  off the axis. The beam then carries an axial load P = F_n (cos psi + mu sin psi) and a
  lateral tip load Q = P tan gamma, and the tip, free to slide, deflects sideways as a
  clamped-free beam-column (:func:`slip_law`): bent from the first touch, with an axial
  capacity near pi^2 EI / (4 L^2), an eighth of the pinned beam's 20.19 EI / L^2. The tissue
  side is ``a = delta_n / cos psi`` (the slide's share of the axial travel, ``w tan psi``,
  is the beam's, in :func:`slip_law`).

``curvature_factor`` scales the normal force for a curved surface (Hertz: sqrt(R*/R_tip), with
1/R* = 1/R_tip + 1/R_surface): applied to any force law as the same factor, an approximation
beyond the Hertz range. :class:`ObliqueContact` wraps any tissue law with the equilibrium
solver's interface (``force_and_stiffness``/``inverse`` on arrays, ``_at`` twins on floats) and
is hashable when the wrapped law is, so the contact tables' cache still works.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .equilibrium.law import AxialLaw, TissueLaw

FloatArray = NDArray[np.float64]

SLIP_GRID = 400  # points of the slip law's load grid
_SLIP_EDGE = 1e-5  # the grid stops at kL = (1 - _SLIP_EDGE) pi/2 (the capacity's divergence)
_BOW_POINTS = 201  # quadrature points of the bow's shortening


def tangential_ratio(poisson: float) -> float:
    """Mindlin's k_t / k_n = 2 (1 - nu) / (2 - nu) for a rigid sphere on an elastic solid."""
    return 2.0 * (1.0 - poisson) / (2.0 - poisson)


@dataclass(frozen=True)
class ObliqueContact:
    """A tissue law seen along a sensor axis at ``psi`` (rad) to the surface normal.

    Attributes:
        law: the tissue's normal force law (delta_n -> F_n).
        psi: angle between the sensor axis and the inward normal at the contact (rad, [0, pi/2)).
        friction: Coulomb coefficient between tip and surface.
        poisson: the tissue's Poisson's ratio (Mindlin's tangential stiffness).
        curvature_factor: scale of the normal force for the surface's own curvature (1: flat).
        sensed: cosine between the slip's lateral direction and the fiber's bending plane
            (signed: which side the slip bends the beam toward).
    """

    law: TissueLaw
    psi: float
    friction: float
    poisson: float
    curvature_factor: float = 1.0
    sensed: float = 0.0

    def __post_init__(self) -> None:
        if not 0.0 <= self.psi < math.pi / 2:
            raise ValueError(f"misalignment psi must be in [0, pi/2) rad, got {self.psi}")
        if not (self.friction >= 0 and self.curvature_factor > 0):
            raise ValueError("friction must be >= 0 and curvature_factor > 0")

    @property
    def sticks(self) -> bool:
        """The friction can carry the tangential load the axis demands."""
        return math.tan(self.psi) <= self.friction

    @property
    def lean(self) -> float:
        """gamma (rad): how far off the axis the tissue's resultant leans (0 when it sticks)."""
        return 0.0 if self.sticks else self.psi - math.atan(self.friction)

    @functools.cached_property
    def _scales(self) -> tuple[float, float]:
        """(g, A): axial travel per normal depth and axial load per unit of the law's force."""
        c, s = math.cos(self.psi), math.sin(self.psi)
        if self.sticks:
            travel = c + s * math.tan(self.psi) / tangential_ratio(self.poisson)
            return travel, self.curvature_factor / c
        return 1.0 / c, self.curvature_factor * (c + self.friction * s)

    def force_and_stiffness(self, a: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """Axial load P (N) and dP/da (N/m) at axial travel ``a`` (m) past the first touch."""
        g, scale = self._scales
        f, k = self.law.force_and_stiffness(np.asarray(a, dtype=np.float64) / g)
        return np.asarray(scale * f), np.asarray(scale * k / g)

    def inverse(self, force: ArrayLike) -> FloatArray:
        """Axial travel (m) at which the axial load is ``force`` (N)."""
        g, scale = self._scales
        return np.asarray(g * self.law.inverse(np.asarray(force, dtype=np.float64) / scale))

    def force_and_stiffness_at(self, a: float) -> tuple[float, float]:
        g, scale = self._scales
        f, k = self.law.force_and_stiffness_at(a / g)
        return scale * f, scale * k / g

    def inverse_at(self, force: float) -> float:
        g, scale = self._scales
        return g * self.law.inverse_at(force / scale)


def _bow(tan_gamma: float, kl: FloatArray, length: float) -> FloatArray:
    """End shortening (m) of the clamped-free beam-column's bow, 1/2 int y'^2, at each kL."""
    u = np.linspace(0.0, 1.0, _BOW_POINTS)[None, :]
    c = np.cos(kl)[:, None]
    slope = tan_gamma * (np.cos(kl[:, None] * (1.0 - u)) - c) / c
    return np.asarray(0.5 * length * np.trapezoid(slope**2, u, axis=1))


def slip_law(contact: ObliqueContact, EI: float, EA: float, length: float) -> AxialLaw | None:
    """The beam of a slipping contact as the equilibrium solver sees it, None when it sticks.

    Linear beam-column, clamped at the tube, loaded at its free tip by P along the axis and
    Q = P tan(gamma) across it; k = sqrt(P/EI). Its tip deflects ``w = tan(gamma) (tan kL -
    kL)/k``, which moves the tip off the surface by ``w sin psi``, and its bow shortens it by
    ``1/2 int y'^2``; the solver's shortening is ``e = P L/EA + bow + w tan psi`` (monotone in
    P, unbounded as kL -> pi/2), inverted on a grid of kL. The onset the solver splits at is
    put at the first grid point: the beam bends from the first touch.
    """
    if contact.sticks:
        return None
    tg = math.tan(contact.lean)
    kl = 0.5 * math.pi * (1.0 - np.geomspace(1.0, _SLIP_EDGE, SLIP_GRID))  # 0 .. below pi/2
    P = EI * (kl / length) ** 2
    k = kl / length
    w = np.where(kl > 0, tg * (np.tan(kl) - kl) / np.where(k > 0, k, 1.0), 0.0)
    e = P * length / EA + _bow(tg, kl, length) + w * math.tan(contact.psi)
    e_grid, p_grid = tuple(e.tolist()), tuple(P.tolist())

    def force(x: FloatArray) -> FloatArray:
        return np.asarray(np.interp(x, e_grid, p_grid))

    def lateral(x: FloatArray) -> FloatArray:
        return np.asarray(tg * np.interp(x, e_grid, p_grid))

    return AxialLaw(
        force=force,
        critical_load=p_grid[1],
        length=length,
        axial_stiffness=EA,
        lateral_force=lateral,
        max_shortening=e_grid[-1],
    )


def slip_strains(
    contact: ObliqueContact,
    P: FloatArray,
    EI: float,
    fiber_offset: float,
    length: float,
    intervals_from_tip: FloatArray,
) -> FloatArray:
    """Grating bending strains (M, G) of the slipping beam-column at loads ``P`` (M,).

    Curvature at distance d from the tip: ``tan(gamma) k sin(k d) / cos(kL)``, averaged over
    each grating's (d0, d1) row of ``intervals_from_tip`` (G, 2) (the part inside the tube, d >
    L, is straight), times the fiber offset and the share of the slip the fiber's plane sees.
    """
    k = np.sqrt(np.maximum(P, 0.0) / EI)[:, None]
    d0 = np.minimum(intervals_from_tip[:, 0], length)[None, :]
    d1 = np.minimum(intervals_from_tip[:, 1], length)[None, :]
    span = (intervals_from_tip[:, 1] - intervals_from_tip[:, 0])[None, :]
    mean = (np.cos(k * d0) - np.cos(k * d1)) / span / np.cos(k * length)
    return np.asarray(-fiber_offset * contact.sensed * math.tan(contact.lean) * mean)
