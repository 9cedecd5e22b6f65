"""A tissue surface as geometry: a plane or a convex sphere, and its fit to touched points.

:class:`SurfaceGeometry` is a point on the surface, the outward unit normal there and, for a
convex sphere, its radius: the robot's belief after probing (``robot.probing``) and the world's
truth (``sim.world``) are both one. :meth:`SurfaceGeometry.ray_hit` is where a ray first meets
the surface; :meth:`SurfaceGeometry.offset` moves it outward, so the centre of a tip sphere of
radius r touches the surface exactly when it reaches ``offset(r)``.

Fits. A light touch gives the tip sphere's *centre* at contact, from the kinematics and the stage
encoder: the centres lie on the surface offset by the tip radius, so the fits run on the centres
and :meth:`SurfaceFit.surface` moves the result back by the tip radius (a plane keeps its
normal; a sphere loses the tip radius from its own). :func:`fit_plane` is the total-least-squares
plane (SVD of the centred points, 3 points or more); :func:`fit_sphere` the algebraic (Kasa)
sphere refined by Gauss-Newton on the geometric distance (4 points or more, not coplanar);
:func:`fit_surface` picks the sphere only when the plane leaves a residual the noise cannot
explain (5 points or more).

Uncertainty. Each touch is uncertain along its own approach ray (the stage encoder and the FBG
contact threshold), by ``sigma`` (m). The fitted normal at the reference point is propagated
linearly: the fit is repeated with each point moved by a small step along its ray, and the
normal's 1-sigma angle is ``sqrt(trace(J J^T)) sigma`` (the rms angle over both tangent axes).
With exactly 3 points a plane fits exactly and ``sigma`` is all there is; with more, the noise
is the larger of ``sigma`` and what the residual shows.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

Vector = NDArray[np.float64]
Model = Literal["plane", "sphere"]

_GN_ITERATIONS = 20
_GN_TOL = 1e-12  # m, on the centre's step
_STEP = 1e-6  # m, the perturbation of a touch for the Jacobian of the normal
PLANE_EXPLAINS = 3.0  # a plane's rms residual within this many sigma needs no sphere


def unit(v: ArrayLike, what: str = "vector") -> Vector:
    """``v`` (3,) scaled to unit length; ValueError if it is not a finite non-zero 3-vector."""
    arr = np.asarray(v, dtype=np.float64)
    norm = float(np.linalg.norm(arr)) if arr.shape == (3,) else math.nan
    if not (math.isfinite(norm) and norm > 0.0):
        raise ValueError(f"{what} must be a finite non-zero 3-vector, got {v!r}")
    return arr / norm


@dataclass(frozen=True)
class SurfaceGeometry:
    """A plane, or a convex sphere, in the robot's base frame (m).

    Attributes:
        point: (3,) a point on the surface.
        normal: (3,) the outward unit normal at ``point``.
        radius: the sphere's radius (m, > 0), None for a plane; the centre is
            ``point - radius * normal``.
    """

    point: Vector
    normal: Vector
    radius: float | None = None

    def __post_init__(self) -> None:
        if self.radius is not None and not (math.isfinite(self.radius) and self.radius > 0):
            raise ValueError(f"sphere radius must be > 0 m or None, got {self.radius}")

    @classmethod
    def make(
        cls, point: ArrayLike, normal: ArrayLike, radius: float | None = None
    ) -> SurfaceGeometry:
        """Checked constructor: ``normal`` is made unit, ``point`` a float (3,) array."""
        p = np.asarray(point, dtype=np.float64)
        if p.shape != (3,) or not np.all(np.isfinite(p)):
            raise ValueError(f"point must be a finite 3-vector, got {point!r}")
        return cls(p, unit(normal, "normal"), radius)

    @property
    def centre(self) -> Vector:
        """The sphere's centre (3,); ValueError for a plane."""
        if self.radius is None:
            raise ValueError("a plane has no centre")
        return np.asarray(self.point - self.radius * self.normal)

    def normal_at(self, p: ArrayLike) -> Vector:
        """The outward unit normal (3,) at (or nearest to) point ``p``."""
        if self.radius is None:
            return self.normal
        return unit(np.asarray(p, dtype=np.float64) - self.centre, "point - centre")

    def offset(self, d: float) -> SurfaceGeometry:
        """The parallel surface ``d`` (m) outward (inward for d < 0)."""
        radius = None if self.radius is None else self.radius + d
        if radius is not None and radius <= 0:
            raise ValueError(f"offset {d} m turns the sphere of radius {self.radius} m inside out")
        return SurfaceGeometry(self.point + d * self.normal, self.normal, radius)

    def ray_hit(self, origin: ArrayLike, direction: ArrayLike) -> float:
        """Signed distance along the unit ``direction`` from ``origin`` to where the ray enters
        the surface (negative when ``origin`` is already past it); ``inf`` when it never does
        (a plane it runs away from or along, a sphere it misses)."""
        o = np.asarray(origin, dtype=np.float64)
        d = np.asarray(direction, dtype=np.float64)
        if self.radius is None:
            approach = float(self.normal @ d)
            if approach >= 0.0:
                return math.inf
            return float(self.normal @ (self.point - o)) / approach
        oc = o - self.centre
        b = float(d @ oc)
        disc = b * b - (float(oc @ oc) - self.radius**2)
        if disc < 0.0:
            return math.inf
        return -b - math.sqrt(disc)

    def distance(self, p: ArrayLike) -> float:
        """Signed distance (m) of ``p`` from the surface, positive outside."""
        q = np.asarray(p, dtype=np.float64)
        if self.radius is None:
            return float(self.normal @ (q - self.point))
        return float(np.linalg.norm(q - self.centre)) - self.radius


@dataclass(frozen=True)
class SurfaceFit:
    """A surface fitted to touched tip-sphere centres.

    Attributes:
        success: False when the points do not determine the model (then ``centres`` is None).
        message: what was fitted, or why not.
        model: "plane" or "sphere".
        centres: the surface through the tip-sphere centres (offset by the tip radius).
        rms: rms distance (m) of the centres from it.
        normal_sigma: 1-sigma angle (rad) of the outward normal at the reference point.
        points: the number of touches used.
        params: the model's free parameters (a sphere of known radius 3; 0: the model's own).
    """

    success: bool
    message: str
    model: Model
    centres: SurfaceGeometry | None = None
    rms: float = math.nan
    normal_sigma: float = math.nan
    points: int = 0
    params: int = 0

    @property
    def free_parameters(self) -> int:
        """The model's free parameters: ``params``, or 0 for the model's own (plane 3, sphere 4)."""
        return self.params or (3 if self.model == "plane" else 4)

    def surface(self, tip_radius: float) -> SurfaceGeometry:
        """The tissue's surface: the fitted centres' surface moved in by ``tip_radius`` (m)."""
        if self.centres is None:
            raise ValueError(f"no surface: {self.message}")
        return self.centres.offset(-tip_radius)


Fitter = Callable[[NDArray[np.float64], Vector], SurfaceGeometry | None]


def _points(points: ArrayLike, need: int) -> NDArray[np.float64]:
    p = np.asarray(points, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3 or not np.all(np.isfinite(p)):
        raise ValueError(f"points must be a finite (N, 3) array, got shape {p.shape}")
    if p.shape[0] < need:
        raise ValueError(f"need at least {need} points, got {p.shape[0]}")
    return p


def _plane(p: NDArray[np.float64], hint: Vector) -> SurfaceGeometry | None:
    centroid = p.mean(axis=0)
    _, s, vt = np.linalg.svd(p - centroid)
    if s[1] <= 1e-9 * max(s[0], 1e-300):
        return None  # collinear: the plane turns freely about the line
    n = vt[2]
    return SurfaceGeometry(centroid, n if n @ hint >= 0 else -n)


def _sphere(p: NDArray[np.float64], hint: Vector) -> SurfaceGeometry | None:
    """Kasa's algebraic sphere, then Gauss-Newton on the geometric distances; the point is the
    sphere's point on the side of ``hint`` (the robot's side)."""
    a = np.column_stack([2.0 * p, np.ones(len(p))])
    sol, _, rank, _ = np.linalg.lstsq(a, np.einsum("ij,ij->i", p, p), rcond=None)
    if rank < 4:
        return None
    c = sol[:3]
    r = math.sqrt(max(float(sol[3] + c @ c), 0.0))
    for _ in range(_GN_ITERATIONS):
        diff = p - c
        dist = np.linalg.norm(diff, axis=1)
        if np.any(dist == 0.0):
            return None
        jac = np.column_stack([-diff / dist[:, None], -np.ones(len(p))])
        step, *_ = np.linalg.lstsq(jac, -(dist - r), rcond=None)
        c, r = c + step[:3], r + float(step[3])
        if float(np.linalg.norm(step)) < _GN_TOL:
            break
    if not (math.isfinite(r) and r > 0):
        return None
    return SurfaceGeometry(c + r * hint, hint, r)


_FITTERS: dict[Model, tuple[int, Fitter]] = {"plane": (3, _plane), "sphere": (4, _sphere)}


def _fit(
    model: Model,
    points: ArrayLike,
    sigma: float,
    directions: ArrayLike | None,
    reference: ArrayLike | None,
    hint: ArrayLike,
) -> SurfaceFit:
    need, fitter = _FITTERS[model]
    return fit_with(fitter, model, need, points, sigma, directions, reference, hint)


def fit_with(
    fitter: Fitter,
    model: Model,
    need: int,
    points: ArrayLike,
    sigma: float,
    directions: ArrayLike | None,
    reference: ArrayLike | None,
    hint: ArrayLike,
    label: str | None = None,
) -> SurfaceFit:
    """A fit by ``fitter`` (points (N, 3), outward hint -> geometry or None) of ``need``
    parameters, with the normal's uncertainty propagated (module docstring); ``label`` names
    the model in the message (the model's name by default)."""
    p = _points(points, need)
    h = unit(hint, "outward hint")
    rays = _rays(p, directions)
    ref = p.mean(axis=0) if reference is None else np.asarray(reference, dtype=np.float64)

    def normal(q: NDArray[np.float64]) -> Vector | None:
        g = fitter(q, h)
        if g is None:
            return None
        return g.normal_at(ref) if g.radius is None else unit(ref - g.centre, "reference")

    geo = fitter(p, h)
    if geo is None:
        why = "collinear" if model == "plane" else "coplanar or degenerate"
        return SurfaceFit(
            False, f"{len(p)} touches are {why}: no {label or model}", model, points=len(p)
        )
    if geo.radius is not None:  # the point nearest the reference, normal outward there
        n_ref = unit(ref - geo.centre, "reference")
        geo = SurfaceGeometry(geo.centre + geo.radius * n_ref, n_ref, geo.radius)
    resid = np.array([geo.distance(q) for q in p])
    rms = float(np.sqrt(np.mean(resid**2)))
    dof = len(p) - need
    noise = max(sigma, rms * math.sqrt(len(p) / dof)) if dof > 0 else sigma
    n0 = normal(p)
    assert n0 is not None  # the fit succeeded on p
    jac = np.zeros((3, len(p)))
    for i in range(len(p)):
        q = p.copy()
        q[i] += _STEP * rays[i]
        ni = normal(q)
        jac[:, i] = 0.0 if ni is None else (ni - n0) / _STEP
    spread = float(np.sqrt(np.sum(jac**2))) * noise
    message = f"{label or model} through {len(p)} touches, rms {rms * 1e6:.1f} um"
    return SurfaceFit(True, message, model, geo, rms, spread, len(p), need)


def _rays(p: NDArray[np.float64], directions: ArrayLike | None) -> NDArray[np.float64]:
    """Unit direction of each touch's uncertainty (N, 3); None: each point's own distance from
    the centroid does not say, so the fitted model's normal is used by the caller's hint."""
    if directions is None:
        return np.zeros_like(p)
    d = np.asarray(directions, dtype=np.float64)
    if d.shape != p.shape:
        raise ValueError(f"directions must have the points' shape {p.shape}, got {d.shape}")
    return np.asarray(d / np.linalg.norm(d, axis=1)[:, None])


def fit_plane(
    points: ArrayLike,
    *,
    sigma: float,
    hint: ArrayLike,
    directions: ArrayLike | None = None,
    reference: ArrayLike | None = None,
) -> SurfaceFit:
    """Plane through ``points`` (N, 3), N >= 3, outward normal on the side of ``hint`` (3,).

    ``sigma`` (m): each point's uncertainty along its ``directions`` row (N, 3) (None: no
    propagation, ``normal_sigma`` 0); ``reference`` (3,): where the normal's uncertainty is
    given (the centroid by default)."""
    return _fit("plane", points, sigma, directions, reference, hint)


def fit_sphere(
    points: ArrayLike,
    *,
    sigma: float,
    hint: ArrayLike,
    directions: ArrayLike | None = None,
    reference: ArrayLike | None = None,
) -> SurfaceFit:
    """Sphere through ``points`` (N, 3), N >= 4 not coplanar; the arguments as
    :func:`fit_plane`. The result's point is the sphere's point nearest ``reference``."""
    return _fit("sphere", points, sigma, directions, reference, hint)


def fit_surface(
    points: ArrayLike,
    *,
    sigma: float,
    hint: ArrayLike,
    directions: ArrayLike | None = None,
    reference: ArrayLike | None = None,
) -> SurfaceFit:
    """The plane, unless 5 points or more show a residual the plane cannot explain (rms above
    ``PLANE_EXPLAINS`` sigma) and a sphere explains it better."""
    plane = fit_plane(points, sigma=sigma, hint=hint, directions=directions, reference=reference)
    n = len(np.asarray(points))
    if n < 5 or not plane.success or plane.rms <= PLANE_EXPLAINS * sigma:
        return plane
    sphere = fit_sphere(points, sigma=sigma, hint=hint, directions=directions, reference=reference)
    return sphere if sphere.success and sphere.rms < plane.rms else plane


def load_crossing(
    advance: ArrayLike, load: ArrayLike, threshold: float, *, grid: int = 200
) -> tuple[float, float] | None:
    """Where a light touch began and where its load reached ``threshold``: ``(x0, x)`` (m) of
    the sphere's contact law ``load = b + c (x - x0)^1.5`` (Hertz, on a baseline b), fitted to
    the whole approach (N,) by least squares; None when it does not rise.

    Why not the first tick above the threshold: with the sensor's few-microstrain noise on a
    soft sample that tick is tens of micrometres early or late, and so is a baseline taken on a
    few ticks. The fit uses every tick, free ones for the baseline, loaded ones for the rise,
    and its mismatch with the real law (layers, large indentation) is the same at every touch
    of one sample, so the touches move together. ``x0`` is searched on a grid of ``grid``
    points over the record, then on a finer one around the best (b and c are linear)."""
    x = np.asarray(advance, dtype=np.float64)
    y = np.asarray(load, dtype=np.float64)
    if x.ndim != 1 or x.shape != y.shape or len(x) < 4 or not np.all(np.isfinite(x + y)):
        raise ValueError("advance and load must be finite 1-D arrays of one length >= 4")
    if not threshold > 0:
        raise ValueError(f"threshold must be > 0, got {threshold}")
    n = float(len(x))
    sy = float(y.sum())

    def best(candidates: NDArray[np.float64]) -> tuple[float, float, float]:
        f = np.clip(x[None, :] - candidates[:, None], 0.0, None) ** 1.5
        sf, sff, sfy = f.sum(axis=1), np.einsum("ij,ij->i", f, f), f @ y
        det = n * sff - sf * sf
        ok = det > 1e-300 * np.maximum(n * sff, 1e-300)
        c = np.where(ok, (n * sfy - sf * sy) / np.where(ok, det, 1.0), 0.0)
        b = (sy - c * sf) / n
        r = np.einsum("ij,ij->i", c[:, None] * f + b[:, None] - y, c[:, None] * f + b[:, None] - y)
        r = np.where(ok, r, np.inf)
        i = int(np.argmin(r))
        return float(candidates[i]), float(c[i]), float(candidates[1] - candidates[0])

    x0, c, cell = best(np.linspace(x.min(), x.max(), grid))
    x0, c, _ = best(np.linspace(x0 - cell, x0 + cell, grid))
    if not c > 0:
        return None
    return x0, float(x0 + (threshold / c) ** (2.0 / 3.0))
