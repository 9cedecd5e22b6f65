"""Kinematics of the mock concentric tube robot: tube, roll, advance <-> sensor tip.

Conventions (docs/architecture.md): base frame B has its origin where the tube leaves the outer
roller gear, x forward along the straight part, z up, y = z x x (so +y is to the left looking
along +x). A tube is a straight part of length l_s then an arc of length l_a turning by its tip
angle alpha; at roll phi = 0 the arc bends toward -z. Roll turns the tube about +x
(right-handed), so the bend direction is (0, sin phi, -cos phi):

* phi = 0: downward (-z);  phi = pi/2: sideways, toward +y (left);  phi = pi: upward (+z).

Sensor tangent at the tube tip: t = (cos a, sin a sin phi, -sin a cos phi). The tube-tip frame
is R = Rx(phi) Ry(alpha): its x axis is t, its z axis the tube's curvature-plane normal side.
The sensor leaves the tube tip straight along t; its exposed length is L = translation -
flush_translation (the translation at which the tip sphere's centre is at the tube tip); the tip
sphere's centre is tube_tip + L t. The arc formulas use sin(a)/a and (1 - cos a)/a written
with ``np.sinc`` so a straight tube (a -> 0) is exact, not a limit.

Inverse kinematics: rolling turns t on a cone of half-angle alpha about x, so for a target
surface with outward normal n the best roll maximises t . (-n): phi* = atan2(-n_y, n_z), and
the residual angle is acos(cos a (-n_x) + sin a |(-n_y, -n_z)|). A tube whose cone contains -n
gives residual 0 (exact orthogonal indentation). The advance then puts the sphere (radius R)
tangent to the surface plane through the target: n . (tip + L t - p) = R.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Final

import numpy as np
import transforms3d
from numpy.typing import NDArray

from ..config.schema import TubeConfig
from ..estimation.pose.surface import SurfaceGeometry

Vector = NDArray[np.float64]

REASONS: Final[dict[int, str]] = {
    0: "reachable",
    1: "the sensor tangent does not point into the surface (residual >= 90 deg)",
    2: "the surface is closer to the tube tip than the tip sphere allows (exposed length < 0)",
    3: "the advance needed is outside the translation limits",
    4: "no roll within the roll limits gives the best alignment",
    5: "no roll of this tube meets the surface within the angle tolerance",
    6: "the orthogonal contact misses the target by more than the position tolerance",
}


@dataclass(frozen=True)
class TipPose:
    """Forward kinematics result; all vectors in base frame B, metres.

    ``tube_tip`` (3,), ``rotation`` (3, 3) tube-tip frame axes as columns (x = tangent),
    ``tangent`` (3,) unit, ``exposed_length`` L, ``sensor_tip`` (3,) centre of the tip sphere.
    """

    tube_tip: Vector
    rotation: NDArray[np.float64]
    tangent: Vector
    exposed_length: float
    sensor_tip: Vector

    def transform(self) -> NDArray[np.float64]:
        """The 4x4 homogeneous transform of the tube-tip frame in B."""
        return np.asarray(transforms3d.affines.compose(self.tube_tip, self.rotation, np.ones(3)))


@dataclass(frozen=True)
class IKSolution:
    """Inverse kinematics result for one target point and surface normal.

    ``roll`` (rad) and ``advance`` (stage translation, m) are the joint values; ``residual`` is
    the angle (rad) between the sensor tangent and -n; ``contact_point`` (3,) where the sphere
    touches the plane and ``miss`` its distance from the target point (m). ``status`` indexes
    :data:`REASONS`; ``reachable`` is ``status == 0`` and ``reason`` its message.
    """

    tube: str
    roll: float
    advance: float
    exposed_length: float
    residual: float
    status: int
    contact_point: Vector
    miss: float

    @property
    def reachable(self) -> bool:
        return self.status == 0

    @property
    def reason(self) -> str:
        return REASONS[self.status]


def _rot_x(phi: float) -> NDArray[np.float64]:
    return np.asarray(transforms3d.axangles.axangle2mat((1.0, 0.0, 0.0), phi))


def _bend(along: Any, angle: Any) -> tuple[Any, Any]:
    """How far the arc has gone forward (x) and down (z) ``along`` its length (m) where it has
    turned by ``angle`` (rad): ``along`` sin(a)/a and -``along`` (1 - cos a)/a, written with
    ``np.sinc`` so a straight arc (a -> 0) is exact; floats or arrays alike."""
    forward_x = along * np.sinc(angle / math.pi)  # sin(a)/a, 1 at a = 0
    down_z = -along * (0.5 * angle * np.sinc(angle / (2.0 * math.pi)) ** 2)  # (1-cos a)/a
    return forward_x, down_z


def tube_tip_in_bend_plane(tube: TubeConfig) -> tuple[Vector, Vector]:
    """Tube tip position and tangent at roll 0, ``(3,)`` each: the arc bends toward -z."""
    a = tube.tip_angle
    dx, dz = _bend(tube.arc_length, a)
    position = np.array([tube.straight_length + float(dx), 0.0, float(dz)])
    tangent = np.array([math.cos(a), 0.0, -math.sin(a)])
    return position, tangent


def tangent(tube: TubeConfig, roll: float) -> Vector:
    """Unit sensor tangent t at the tube tip for ``roll`` (rad), ``(3,)``."""
    a = tube.tip_angle
    return np.array([math.cos(a), math.sin(a) * math.sin(roll), -math.sin(a) * math.cos(roll)])


def forward(tube: TubeConfig, roll: float, translation: float) -> TipPose:
    """Tube tip frame, tangent, exposed length and tip-sphere centre for a joint state."""
    rx = _rot_x(roll)
    ry = np.asarray(transforms3d.axangles.axangle2mat((0.0, 1.0, 0.0), tube.tip_angle))
    rotation = rx @ ry
    p0, _ = tube_tip_in_bend_plane(tube)
    tip = rx @ p0
    t = rotation[:, 0]
    exposed = translation - tube.flush_translation
    return TipPose(tip, rotation, t, exposed, tip + exposed * t)


def best_roll(tube: TubeConfig, normal: Vector) -> tuple[float, float]:
    """``(roll, residual)``: the roll in (-pi, pi] that best aligns t with -normal, and the
    remaining angle (rad). For a straight tube or a normal along x any roll is as good: 0."""
    m = -_unit(normal)
    lateral = math.hypot(m[1], m[2])
    a = tube.tip_angle
    if a == 0.0 or lateral < 1e-15:
        roll = 0.0
    else:
        roll = math.atan2(m[1], -m[2])
        if roll <= -math.pi + 1e-12:
            roll = math.pi
    cos_res = math.cos(a) * m[0] + math.sin(a) * lateral
    return roll, math.acos(max(-1.0, min(1.0, cos_res)))


def body_points(tube: TubeConfig, roll: float, translation: float, n: int = 24) -> Vector:
    """Points (k, 3) along what the robot puts in front of its base at a joint state: the
    tube's straight part, its arc (``n`` points each) and the sensor out to its tip sphere's
    centre, for checking that they keep clear of tissue (``robot.positioner``)."""
    ls, la = tube.straight_length, tube.arc_length
    straight = np.outer(np.linspace(0.0, ls, n), (1.0, 0.0, 0.0))
    s = np.linspace(0.0, la, n + 1)[1:]
    dx, dz = _bend(s, tube.tip_angle * s / la if la > 0 else np.zeros_like(s))
    arc = np.column_stack([ls + dx, np.zeros_like(s), dz])
    pose = forward(tube, 0.0, translation)
    steps = np.linspace(0.0, max(pose.exposed_length, 0.0), n + 1)[1:, None]
    sensor = pose.tube_tip + steps * pose.tangent
    return np.asarray(np.vstack([straight, arc, sensor]) @ _rot_x(roll).T)


def apex(tube: TubeConfig) -> Vector | None:
    """The point (3,) of the x axis every tip tangent line of a bent tube passes through, at any
    roll (None for a straight tube, whose only line is the x axis itself)."""
    if tube.tip_angle == 0.0:
        return None
    p0, t0 = tube_tip_in_bend_plane(tube)
    return np.asarray(p0 - (p0[2] / t0[2]) * t0)


def solve_for_tube(
    tube: TubeConfig,
    target: Vector,
    normal: Vector,
    *,
    tip_radius: float,
    translation_limits: tuple[float, float],
    roll_limits: tuple[float, float] = (-math.pi, math.pi),
    radius: float | None = None,
    max_residual: float | None = None,
    max_miss: float | None = None,
) -> IKSolution:
    """IK with a given tube: best roll, then the advance where the tip sphere touches the plane
    through ``target`` (3,) with outward unit ``normal`` (3,) there, or the convex sphere of
    ``radius`` (m) through it. ``max_residual`` (rad) and ``max_miss`` (m), when given, are
    part of reachability (statuses 5 and 6)."""
    if not tip_radius >= 0:
        raise ValueError(f"tip_radius must be >= 0, got {tip_radius}")
    p = np.asarray(target, dtype=float)
    n = _unit(normal)
    if radius is None:
        sol = _on_plane(tube, p, n, tip_radius, roll_limits)
    else:
        sol = _on_sphere(tube, SurfaceGeometry.make(p, n, radius), tip_radius, roll_limits)
    status = sol.status
    if status == 0 and sol.exposed_length < 0:
        status = 2
    lo, hi = translation_limits
    if status == 0 and not lo <= sol.advance <= hi:
        status = 3
    if status == 0 and max_residual is not None and sol.residual > max_residual:
        status = 5
    if status == 0 and max_miss is not None and sol.miss > max_miss:
        status = 6
    return dataclasses.replace(sol, status=status)


def roll_for(
    tube: TubeConfig, n: Vector, roll_limits: tuple[float, float]
) -> tuple[float, float, int]:
    """(roll, residual, status 0 or 4) of the best roll within ``roll_limits`` for the outward
    normal ``n``: :func:`best_roll`, turned by whole turns into the limits (status 4 if none)."""
    roll, residual = best_roll(tube, n)
    fitted = _fit_roll(roll, roll_limits)
    return (roll, residual, 4) if fitted is None else (fitted, residual, 0)


def _on_plane(
    tube: TubeConfig, p: Vector, n: Vector, tip_radius: float, roll_limits: tuple[float, float]
) -> IKSolution:
    roll, residual, status = roll_for(tube, n, roll_limits)
    pose = forward(tube, roll, tube.flush_translation)
    approach = float(n @ pose.tangent)  # = -cos(residual)
    if approach > -1e-12:
        return IKSolution(tube.name, roll, math.nan, math.nan, residual, 1, p.copy(), math.inf)
    exposed = (tip_radius - float(n @ (pose.tube_tip - p))) / approach
    advance = tube.flush_translation + exposed
    centre = pose.tube_tip + exposed * pose.tangent
    contact = centre - tip_radius * n
    miss = float(np.linalg.norm(contact - p))
    return IKSolution(tube.name, roll, advance, exposed, residual, status, contact, miss)


def _on_sphere(
    tube: TubeConfig, surface: SurfaceGeometry, tip_radius: float, roll_limits: tuple[float, float]
) -> IKSolution:
    """The roll whose line passes nearest the sphere's centre (through the cone's apex), then
    where the tip sphere meets it and the angle to the normal there."""
    centre_of_sphere = surface.centre
    x = apex(tube)
    towards = surface.normal if x is None else _unit(x - centre_of_sphere)
    roll, _, status = roll_for(tube, towards, roll_limits)
    pose = forward(tube, roll, tube.flush_translation)
    exposed = surface.offset(tip_radius).ray_hit(pose.tube_tip, pose.tangent)
    if not math.isfinite(exposed):
        return IKSolution(
            tube.name, roll, math.nan, math.nan, math.pi / 2, 1, surface.point, math.inf
        )
    centre = pose.tube_tip + exposed * pose.tangent
    n_local = surface.normal_at(centre)
    residual = math.acos(max(-1.0, min(1.0, -float(n_local @ pose.tangent))))
    contact = centre - tip_radius * n_local
    miss = float(np.linalg.norm(contact - surface.point))
    advance = tube.flush_translation + exposed
    return IKSolution(tube.name, roll, advance, exposed, residual, status, contact, miss)


def inverse(
    tubes: Sequence[TubeConfig],
    target: Vector,
    normal: Vector,
    *,
    tip_radius: float,
    translation_limits: tuple[float, float],
    roll_limits: tuple[float, float] = (-math.pi, math.pi),
    radius: float | None = None,
    max_residual: float | None = None,
    max_miss: float | None = None,
) -> IKSolution:
    """Choose the tube and roll whose tangent is best anti-parallel to ``normal``.

    The smallest residual among reachable solutions wins (ties: the tube listed first); when
    none is reachable, the smallest-residual solution is returned with its status. ``radius``,
    ``max_residual`` and ``max_miss`` as in :func:`solve_for_tube`.
    """
    if not tubes:
        raise ValueError("inverse kinematics needs at least one tube")
    solutions = [
        solve_for_tube(
            t,
            target,
            normal,
            tip_radius=tip_radius,
            translation_limits=translation_limits,
            roll_limits=roll_limits,
            radius=radius,
            max_residual=max_residual,
            max_miss=max_miss,
        )
        for t in tubes
    ]
    reachable = [s for s in solutions if s.reachable]
    pool = reachable or solutions
    best = min(range(len(pool)), key=lambda i: (round(pool[i].residual, 12), i))
    return pool[best]


def _unit(v: Vector) -> Vector:
    arr = np.asarray(v, dtype=float)
    norm = float(np.linalg.norm(arr))
    if arr.shape != (3,) or not math.isfinite(norm) or norm == 0.0:
        raise ValueError(f"expected a finite non-zero 3-vector, got {v!r}")
    return arr / norm


def _fit_roll(roll: float, limits: tuple[float, float]) -> float | None:
    """``roll`` + 2 pi k inside ``limits``: ``roll`` itself if it fits, else the one nearest 0;
    None if there is none."""
    lo, hi = limits
    candidates = [roll + 2.0 * math.pi * k for k in (0, -1, 1, -2, 2, -3, 3)]
    inside = [r for r in candidates if lo - 1e-12 <= r <= hi + 1e-12]
    if not inside:
        return None
    return inside[0] if inside[0] == roll else min(inside, key=abs)
