"""Where the simulator puts a robot trial's sample: the plan's target, tilted and moved as the
scene says (the controller is told none of it; ``robot.probing`` finds the surface).

The plan aims the trial's tube, at the campaign's roll, at a target on its tip tangent t0 (the
nominal approach); the plan believes the surface is there and faces the tube (normal -t0). The
sample's truth (``config.sample.SampleConfig``) departs from that: its surface passes through
the target moved by ``offset_mm``, with its outward normal tilted by ``tilt_deg`` from -t0,
toward the azimuth ``tilt_azimuth_deg`` measured about t0 from e1 = dt/d(alpha) (the way the
tube's bend angle grows) toward e2 = t0 x e1; ``curvature_radius_mm`` makes it a convex sphere
with that normal at the point.

A tube meets a surface orthogonally only along one line: every line its rolls give passes
through the cone's apex (``robot.kinematics.apex``), so on a plane it is the perpendicular from
the apex and on a sphere the line through the apex and the centre, and that line must lie on
the tube's cone (at the tube's bend angle from the x axis). ``tilt_azimuth_deg: null`` places
the sample at the azimuth where it does, so that a re-planned roll of the trial's own tube is
orthogonal (the side, + or -, from the trial's seed); where no azimuth does (a straight tube and
any tilt, a tilt beyond twice the tube's angle), the azimuth nearest to it.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from palpate.config.sample import SampleConfig
from palpate.config.schema import TubeConfig
from palpate.robot import kinematics
from palpate.sim.world import Surface

Vector = NDArray[np.float64]
_AZIMUTHS = 721  # grid of the azimuth search


def tilt_frame(
    tube: TubeConfig, roll: float, t0: Vector | None = None
) -> tuple[Vector, Vector, Vector]:
    """(t0, e1, e2): the nominal tangent (``t0``, or the tube's at ``roll``), the way the bend
    angle grows, and t0 x e1."""
    t0 = kinematics.tangent(tube, roll) if t0 is None else t0
    a = tube.tip_angle
    e1 = np.array([-math.sin(a), math.cos(a) * math.sin(roll), -math.cos(a) * math.cos(roll)])
    return t0, e1, np.cross(t0, e1)


def tilted_normal(frame: tuple[Vector, Vector, Vector], tilt: float, azimuth: float) -> Vector:
    """The outward normal tilted by ``tilt`` (rad) from -t0 toward ``azimuth`` (rad)."""
    t0, e1, e2 = frame
    way = math.cos(azimuth) * e1 + math.sin(azimuth) * e2
    return np.asarray(-(math.cos(tilt) * t0 + math.sin(tilt) * way))


def _orthogonal_direction(
    tube: TubeConfig, point: Vector, normal: Vector, radius: float | None
) -> Vector:
    """The direction a tube must point in to meet this surface orthogonally (from its apex)."""
    apex = kinematics.apex(tube)
    if radius is None or apex is None:
        return -normal
    to_centre = point - radius * normal - apex
    return np.asarray(to_centre / np.linalg.norm(to_centre))


def _bisect(f: Callable[[float], float], lo: float, hi: float) -> float:
    """A root of ``f`` in [lo, hi], where it changes sign (to 1e-13 rad)."""
    f_lo = f(lo)
    while hi - lo > 1e-13:
        mid = 0.5 * (lo + hi)
        f_mid = f(mid)
        if f_mid == 0.0:
            return mid
        if (f_mid < 0.0) == (f_lo < 0.0):
            lo, f_lo = mid, f_mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def reachable_azimuth(
    tube: TubeConfig,
    roll: float,
    point: Vector,
    sample: SampleConfig,
    side: int,
) -> float:
    """The azimuth (rad) at which a roll of ``tube`` meets the tilted sample orthogonally: the
    root on the ``side`` (+1 or -1) of the nominal roll, or the azimuth that comes nearest."""
    frame = tilt_frame(tube, roll)
    tilt, radius = sample.tilt, sample.curvature_radius

    def off_cone(beta: float) -> float:
        d = _orthogonal_direction(tube, point, tilted_normal(frame, tilt, beta), radius)
        return math.acos(max(-1.0, min(1.0, float(d[0])))) - tube.tip_angle

    betas = np.linspace(-math.pi, math.pi, _AZIMUTHS)
    values = np.array([off_cone(b) for b in betas])
    roots = [
        _bisect(off_cone, float(betas[i]), float(betas[i + 1]))
        for i in range(len(betas) - 1)
        if values[i] == 0.0 or values[i] * values[i + 1] < 0.0
    ]
    if not roots:
        return float(betas[int(np.argmin(np.abs(values)))])
    wanted = [r for r in roots if (r >= 0) == (side > 0)] or roots
    return wanted[0]


def place_sample(
    tube: TubeConfig,
    roll: float,
    nominal: tuple[Vector, Vector],
    sample: SampleConfig,
    seed: int,
) -> Surface:
    """The sample's surface for a trial that aims ``tube`` at ``roll`` (rad) at a target along
    a tangent, ``nominal`` = (target (3,), t0 (3,))."""
    target, t0 = nominal
    point = target if sample.offset == (0.0, 0.0, 0.0) else target + np.asarray(sample.offset)
    frame = tilt_frame(tube, roll, t0)
    if sample.tilt == 0.0:
        return Surface(point=point, normal=-frame[0], radius=sample.curvature_radius)
    azimuth = sample.tilt_azimuth
    if azimuth is None:
        azimuth = reachable_azimuth(tube, roll, point, sample, 1 if seed % 2 == 0 else -1)
    normal = tilted_normal(frame, sample.tilt, azimuth)
    return Surface(point=point, normal=normal, radius=sample.curvature_radius)
