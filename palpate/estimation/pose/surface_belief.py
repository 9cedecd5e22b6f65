"""A convex sample's normal from one tube's touches and the radius the operator believes.

Every ray a tube's rolls give passes through its cone's apex, so a tube's touches trace one curve
on the surface: cone and sphere meet in a curve so nearly a circle that a plane fits it to a few
micrometres while its normal is 20-50 deg off the sphere's (``docs/oblique.md``). Along the roll
the touches still tell where the ray meets the surface square (the nearest touch), but the
sphere's tilt across the cone is not observable from them: a sphere of another radius and a
centre off the cone traces nearly the same curve. With the radius known that tilt is: one
degree across moves the touches of a 30-100 mm sphere by 20-70 um against a touch's few um.

:func:`fit_sphere_of_radius` fits the centre of a sphere of given radius (three parameters):
the touches' plane cuts the sphere in a circle whose centre is the projection of the sphere's,
so the start is that circle's centre moved behind the plane (away from the robot) by
``sqrt(R^2 - rho^2)``, then Gauss-Newton on the geometric distances. A radius believed as a
range ``(min, max)`` is fitted at both ends and the middle: the middle's normal is the answer
and the angle the range turns it through (the larger of the two ends') is added to its 1-sigma
in quadrature: what the belief leaves open is part of the normal's doubt, never hidden.

The radii here are the tip-sphere centres' (the surface's plus the tip radius): the caller
passes ``SurfaceFit.surface(tip_radius)`` on as the tissue's.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .surface import Fitter, SurfaceFit, SurfaceGeometry, Vector, fit_with, unit

_GN_ITERATIONS = 30
_GN_TOL = 1e-13  # m, on the centre's step


def sphere_of_radius(radius: float) -> Fitter:
    """A fitter (points (N, 3), outward hint -> sphere or None) for a sphere of ``radius`` (m)
    through the points, its centre on the far side of the points from the hint."""
    if not (math.isfinite(radius) and radius > 0):
        raise ValueError(f"radius must be a finite length > 0 m, got {radius}")

    def fitter(p: NDArray[np.float64], hint: Vector) -> SurfaceGeometry | None:
        c = _start(p, hint, radius)
        if c is None:
            return None
        for _ in range(_GN_ITERATIONS):
            diff = p - c
            dist = np.linalg.norm(diff, axis=1)
            if np.any(dist == 0.0):
                return None
            step, *_ = np.linalg.lstsq(-diff / dist[:, None], -(dist - radius), rcond=None)
            c = c + step
            if float(np.linalg.norm(step)) < _GN_TOL:
                break
        if not np.all(np.isfinite(c)):
            return None
        return SurfaceGeometry(c + radius * hint, hint, radius)

    return fitter


def _start(p: NDArray[np.float64], hint: Vector, radius: float) -> Vector | None:
    """The centre from the circle the points' plane cuts from the sphere (module docstring)."""
    m = p.mean(axis=0)
    _, s, vt = np.linalg.svd(p - m)
    if s[1] <= 1e-9 * max(s[0], 1e-300):
        return None  # collinear: no circle
    n = vt[2] if vt[2] @ hint >= 0 else -vt[2]
    e1, e2 = vt[0], vt[1]
    q = np.column_stack([(p - m) @ e1, (p - m) @ e2])
    a = np.column_stack([2.0 * q, np.ones(len(q))])
    sol, _, rank, _ = np.linalg.lstsq(a, np.einsum("ij,ij->i", q, q), rcond=None)
    if rank < 3:
        return None
    x, y = float(sol[0]), float(sol[1])
    rho2 = float(sol[2]) + x * x + y * y
    behind = math.sqrt(max(radius * radius - rho2, 0.0))
    return np.asarray(m + x * e1 + y * e2 - behind * n)


def fit_sphere_of_radius(
    points: ArrayLike,
    radii: tuple[float, float],
    *,
    sigma: float,
    hint: ArrayLike,
    directions: ArrayLike | None = None,
    reference: ArrayLike | None = None,
) -> SurfaceFit:
    """A sphere of radius in ``radii`` (min, max; m, the centres') through ``points`` (N, 3),
    N >= 3; the other arguments as :func:`estimation.pose.surface.fit_plane`. The radii's middle
    is fitted; with a range, the angle its ends turn the normal at ``reference`` through is
    added to ``normal_sigma`` in quadrature (module docstring)."""
    lo, hi = radii
    if not (0 < lo <= hi and math.isfinite(hi)):
        raise ValueError(f"radii must be 0 < min <= max < inf (m), got {radii}")
    mid = 0.5 * (lo + hi)
    ref = np.asarray(points, dtype=np.float64).mean(axis=0) if reference is None else reference

    def fit(radius: float) -> SurfaceFit:
        label = f"sphere of the believed radius (the tip centres' {radius * 1e3:.1f} mm)"
        return fit_with(
            sphere_of_radius(radius), "sphere", 3, points, sigma, directions, ref, hint, label
        )

    best = fit(mid)
    if not best.success or best.centres is None or hi == lo:
        return best
    n_mid = _normal(best.centres, ref)
    turned = 0.0
    for end in (lo, hi):
        other = fit(end)
        if not other.success or other.centres is None:
            return dataclasses.replace(
                best, success=False, centres=None,
                message=f"the believed radius's end (the tip centres' {end * 1e3:.1f} mm) does "
                f"not fit: {other.message}",
            )  # fmt: skip
        cos = float(np.clip(n_mid @ _normal(other.centres, ref), -1.0, 1.0))
        turned = max(turned, math.acos(cos))
    message = (
        f"{best.message}; the believed radius's range turns the normal by "
        f"{math.degrees(turned):.2f} deg"
    )
    return dataclasses.replace(
        best, message=message, normal_sigma=math.hypot(best.normal_sigma, turned)
    )


def _normal(sphere: SurfaceGeometry, reference: ArrayLike) -> Vector:
    return unit(np.asarray(reference, dtype=np.float64) - sphere.centre, "reference")
