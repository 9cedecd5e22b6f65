"""The robot on a positioning stage: a tube, a roll and a stage pose that put the sensor on a
point of the tissue along its normal (issue 58).

In a body the tissue cannot be moved; the robot is carried instead, by a lab's gantry on the
bench or by a bronchoscope or guide sheath in the body: insertion along the base frame's x and
lateral travel in y and z (:class:`Positioner`). The stage moves the robot's base frame B
(``robot.kinematics``) by ``base`` (3,) in the world frame, which B matches at stage zero.

:func:`place` solves, for one :class:`maps.surfaces.SurfacePoint` (a point and its outward
normal ``n``):

1. each tube's best roll (:func:`robot.kinematics.roll_for`): the tangent's residual angle to
   ``-n`` is then set by the tube's cone alone, wherever the stage is;
2. the base that puts the tip sphere's centre at ``point + R n`` with the sensor out by the
   contact's exposed length (``exposed_length``): the sphere then touches the tissue at the
   point itself, whatever the residual (a plane; on a curved surface to first order);
3. the start: backed off along the tangent until the sphere is ``standoff`` clear of the tissue
   along the normal; the translation there and at contact within ``translation_limits``;
4. the stage's travel, and the clearance of the tube and sensor (``robot.kinematics.body_points``)
   from the tissue at the start (``surface.clearance`` above ``body_radius``; the sphere's
   own ``R``).

The tube with the smallest residual among those that pass wins; a point no tube reaches within
``max_residual`` is returned with status 1 (the tube that comes closest): probe it obliquely
with a verdict that says so, or skip it. Statuses index :data:`PLACE_REASONS`::

    airway = Lumen(origin=(0, 0, 0), axis=(1, 0, 0), radius=6e-3)
    stage = Positioner(x=(-0.05, 0.05), y=(-4e-3, 4e-3), z=(-4e-3, 4e-3))
    how = Approach(tip_radius=1.3e-3, exposed_length=4e-3, standoff=1e-3,
                   translation_limits=(0.0, 0.03), surface=airway)
    p = place(stack.tubes, airway.at(12e-3, 0.0), stage, how)
    p.reachable, p.tube, math.degrees(p.residual), p.base
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..config.schema import TubeConfig
from ..maps.surfaces import Surface, SurfacePoint
from .kinematics import body_points, forward, roll_for

Vector = NDArray[np.float64]
Limits = tuple[float, float]

PLACE_REASONS = {
    0: "reachable",
    1: "no tube meets the normal within the angle tolerance (oblique)",
    2: "the stage's travel does not reach the base this needs",
    3: "the translation needed is outside the translation limits",
    4: "no roll within the roll limits gives the best alignment",
    5: "the tube or sensor would touch the tissue on the way in",
    6: "the sensor's tangent does not point into the tissue",
}
MAX_RESIDUAL = math.radians(2.0)  # the orthogonality tolerance


@dataclass(frozen=True)
class Positioner:
    """The stage that carries the robot: the base's travel along x (insertion), y and z, each
    ``(min, max)`` m, in the world frame."""

    x: Limits
    y: Limits = (0.0, 0.0)
    z: Limits = (0.0, 0.0)

    def __post_init__(self) -> None:
        for axis, (lo, hi) in zip("xyz", (self.x, self.y, self.z), strict=True):
            if not lo <= hi:
                raise ValueError(f"positioner {axis} travel [{lo}, {hi}] m is not [min, max]")

    @property
    def home(self) -> Vector:
        """The base at stage zero, where the robot's base frame is the world's."""
        return np.zeros(3)

    def holds(self, base: Vector, slack: float = 1e-12) -> bool:
        """Whether ``base`` (3,) is within the travel."""
        return all(
            lo - slack <= float(b) <= hi + slack
            for b, (lo, hi) in zip(base, (self.x, self.y, self.z), strict=True)
        )


@dataclass(frozen=True)
class Placement:
    """Where to put the robot for one point: the tube and roll (rad), the stage's ``base``
    (3,) m, the translation at the start (``standoff`` clear) and at contact (m), the residual
    angle between the tangent and ``-n`` (rad), the least clearance of the tube and sensor from
    the tissue at the start (m, less ``body_radius``), and the status."""

    tube: str
    roll: float
    base: Vector
    start_translation: float
    contact_translation: float
    residual: float
    clearance: float
    status: int

    @property
    def reachable(self) -> bool:
        return self.status == 0

    @property
    def reason(self) -> str:
        return PLACE_REASONS[self.status]


@dataclass(frozen=True)
class Approach:
    """How the sensor meets a point: its tip sphere's radius, how far it is out at contact
    (``exposed_length``), how far clear it starts (``standoff``, along the normal), the drive's
    translation limits and roll limits, the tissue to keep clear of (``surface``, None: no
    check) and the tube's and sensor's own radius there (``body_radius``), and the largest
    angle to the normal that counts as square on (``max_residual``); SI."""

    tip_radius: float
    exposed_length: float
    standoff: float
    translation_limits: Limits
    surface: Surface | None = None
    body_radius: float = 0.0
    roll_limits: Limits = (-math.pi, math.pi)
    max_residual: float = MAX_RESIDUAL

    def __post_init__(self) -> None:
        if not (self.tip_radius > 0 and min(self.exposed_length, self.standoff) >= 0):
            raise ValueError("tip_radius must be > 0 m and exposed_length, standoff >= 0 m")
        if not self.body_radius >= 0:
            raise ValueError(f"body_radius must be >= 0 m, got {self.body_radius!r}")


def place_with_tube(
    tube: TubeConfig, target: SurfacePoint, stage: Positioner, how: Approach
) -> Placement:
    """:func:`place` with one tube."""
    n = np.asarray(target.normal, dtype=np.float64)
    roll, residual, status = roll_for(tube, n, how.roll_limits)
    contact = tube.flush_translation + how.exposed_length
    pose = forward(tube, roll, contact)
    approach = -float(n @ pose.tangent)  # cos(residual)
    base = np.asarray(target.point + how.tip_radius * n - pose.sensor_tip, dtype=np.float64)
    start = contact - how.standoff / approach if approach > 1e-9 else math.nan
    clearance = math.inf
    if status == 0 and approach <= 1e-9:
        status = 6
    lo, hi = how.translation_limits
    if status == 0 and not (lo <= start and contact <= hi):
        status = 3
    if status == 0 and not stage.holds(base):
        status = 2
    if how.surface is not None and math.isfinite(start):
        clearance = _clearance(tube, roll, start, base, how)
        if status == 0 and clearance < 0.0:
            status = 5
    if status == 0 and residual > how.max_residual:
        status = 1
    return Placement(tube.name, roll, base, start, contact, residual, clearance, status)


def place(
    tubes: Sequence[TubeConfig], target: SurfacePoint, stage: Positioner, how: Approach
) -> Placement:
    """The tube, roll and stage pose for ``target`` (the module docstring): the reachable
    placement with the smallest residual (ties: the tube listed first); else the oblique one
    (status 1) with the smallest; else the refusal with the smallest residual."""
    if not tubes:
        raise ValueError("placing the robot needs at least one tube")
    found = [place_with_tube(t, target, stage, how) for t in tubes]
    for wanted in ((0,), (1,), tuple(PLACE_REASONS)):
        pool = [p for p in found if p.status in wanted]
        if pool:
            return min(pool, key=lambda p: round(p.residual, 12))
    raise AssertionError("unreachable: every status is in PLACE_REASONS")


def _clearance(
    tube: TubeConfig, roll: float, translation: float, base: Vector, how: Approach
) -> float:
    """The least clearance (m) of the tube and sensor (less the body's radius) and of the tip
    sphere (less its radius) from ``how.surface``, at ``translation`` with the stage at
    ``base``."""
    assert how.surface is not None
    body = body_points(tube, roll, translation) + base  # its last point: the sphere's centre
    gaps = how.surface.clearance(body)
    return min(float(np.min(gaps[:-1])) - how.body_radius, float(gaps[-1]) - how.tip_radius)
