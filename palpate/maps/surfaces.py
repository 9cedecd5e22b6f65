"""Tissue that faces any way, in its own coordinates: a tilted plane, a convex dome, a lumen.

A map through the robot (issue 58) picks its points on the surface, in the surface's own
coordinates ``(u, v)`` (m), and asks the surface where that is and which way it faces:

* :class:`TiltedPlane`: ``u`` and ``v`` along two orthogonal directions in the plane.
* :class:`Dome`: a convex sphere's cap; ``(u, v)`` the azimuthal equidistant coordinates about
  its apex (``hypot(u, v)`` is the arc length from the apex along the surface).
* :class:`Lumen`: the inside of a tube (an airway); ``u`` the insertion along its axis, ``v``
  the arc length around its wall from a first radial direction.

Every point is a :class:`SurfacePoint`: where it is and the outward unit normal there, out of
the tissue into free space (for a lumen, toward its axis). :meth:`clearance` is the signed
distance of points from the tissue, positive in free space: what a path must keep above the
radius of what moves along it. Pure geometry, SI, in the frame the surface is given in::

    airway = Lumen(origin=(0.0, 0.0, 0.0), axis=(1.0, 0.0, 0.0), radius=6e-3)
    p = airway.at(10e-3, 0.5 * math.pi * 6e-3)   # 10 mm in, a quarter turn round the wall
    p.point, p.normal                              # (0.01, 0.006, 0), (0, -1, 0)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

Vector = NDArray[np.float64]


def _unit(v: ArrayLike, what: str) -> Vector:
    arr = np.asarray(v, dtype=np.float64)
    norm = float(np.linalg.norm(arr)) if arr.shape == (3,) else math.nan
    if not (math.isfinite(norm) and norm > 0.0):
        raise ValueError(f"{what} must be a finite non-zero 3-vector, got {v!r}")
    return arr / norm


def _frame(axis: Vector, first: ArrayLike | None) -> tuple[Vector, Vector]:
    """Two unit vectors completing ``axis`` to a right-handed frame, the first along ``first``
    projected off the axis (any perpendicular direction if None)."""
    if first is None:
        trial = np.eye(3)[int(np.argmin(np.abs(axis)))]
    else:
        trial = np.asarray(first, dtype=np.float64)
    e1 = trial - float(trial @ axis) * axis
    e1 = _unit(e1, "the first direction (off the axis)")
    return e1, np.cross(axis, e1)


@dataclass(frozen=True)
class SurfacePoint:
    """A point on the tissue (3,) and the outward unit normal there (3,), m."""

    point: Vector
    normal: Vector


class Surface(Protocol):
    """Tissue a map runs over, in its own coordinates."""

    def at(self, u: float, v: float) -> SurfacePoint: ...

    def clearance(self, points: ArrayLike) -> NDArray[np.float64]: ...


@dataclass(frozen=True)
class TiltedPlane:
    """A plane through ``origin`` with outward ``normal``; ``u`` along ``first`` (projected
    into the plane), ``v`` along ``normal x first``."""

    origin: ArrayLike
    normal: ArrayLike
    first: ArrayLike | None = None
    _n: Vector = field(init=False, repr=False)
    _e: tuple[Vector, Vector] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        n = _unit(self.normal, "normal")
        object.__setattr__(self, "_n", n)
        object.__setattr__(self, "_e", _frame(n, self.first))

    def at(self, u: float, v: float) -> SurfacePoint:
        e1, e2 = self._e
        return SurfacePoint(np.asarray(self.origin, float) + u * e1 + v * e2, self._n.copy())

    def clearance(self, points: ArrayLike) -> NDArray[np.float64]:
        x = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        return np.asarray((x - np.asarray(self.origin, float)) @ self._n)


@dataclass(frozen=True, kw_only=True)
class _AboutAnAxis:
    """A shape of ``radius`` about ``axis`` (unit: ``_a``), with a frame ``_e`` about it whose
    first direction is ``first`` (projected off the axis; any if None): a dome's, a lumen's."""

    axis: ArrayLike
    radius: float
    first: ArrayLike | None = None
    _a: Vector = field(init=False, repr=False)
    _e: tuple[Vector, Vector] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        if not self.radius > 0:
            raise ValueError(f"radius must be > 0 m, got {self.radius!r}")
        a = _unit(self.axis, "axis")
        object.__setattr__(self, "_a", a)
        object.__setattr__(self, "_e", _frame(a, self.first))

    def around(self, angle: float) -> Vector:
        """The unit direction off the axis ``angle`` (rad) round from ``first``."""
        e1, e2 = self._e
        return np.asarray(math.cos(angle) * e1 + math.sin(angle) * e2)


@dataclass(frozen=True)
class Dome(_AboutAnAxis):
    """A convex sphere of ``radius`` whose ``apex`` faces along ``axis`` (outward there)."""

    apex: ArrayLike

    @property
    def centre(self) -> Vector:
        return np.asarray(np.asarray(self.apex, float) - self.radius * self._a)

    def at(self, u: float, v: float) -> SurfacePoint:
        polar = math.hypot(u, v) / self.radius
        if polar >= math.pi:
            raise ValueError(f"({u:.4g}, {v:.4g}) m is past the dome's far pole")
        side = self.around(math.atan2(v, u))
        n = math.cos(polar) * self._a + math.sin(polar) * side
        return SurfacePoint(self.centre + self.radius * n, n)

    def clearance(self, points: ArrayLike) -> NDArray[np.float64]:
        x = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        return np.asarray(np.linalg.norm(x - self.centre, axis=1) - self.radius)


@dataclass(frozen=True)
class Lumen(_AboutAnAxis):
    """The inside wall of a straight tube of ``radius`` about the line through ``origin``
    along ``axis``; ``v`` runs round the wall from ``first`` (right-handed about the axis)."""

    origin: ArrayLike

    def at(self, u: float, v: float) -> SurfacePoint:
        radial = self.around(v / self.radius)
        point = np.asarray(self.origin, float) + u * self._a + self.radius * radial
        return SurfacePoint(point, -radial)

    def clearance(self, points: ArrayLike) -> NDArray[np.float64]:
        x = np.asarray(points, dtype=np.float64).reshape(-1, 3) - np.asarray(self.origin, float)
        off_axis = x - np.outer(x @ self._a, self._a)
        return np.asarray(self.radius - np.linalg.norm(off_axis, axis=1))
