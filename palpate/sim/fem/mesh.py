"""The layer's mesh: triangles graded toward the first point of contact.

A tensor grid whose spacing grows geometrically away from the axis and the surface is refined
(conforming red-green-blue refinement, ``skfem.MeshTri.refined``) until every triangle near the
contact is no larger than ``distance / resolution`` from the origin (the point the sphere first
touches), with a floor at the smallest tabulated contact radius. The indentation problem is
nearly self-similar (the contact radius sets the length scale), so a size proportional to the
distance keeps the same number of elements per contact radius at every depth.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from skfem import MeshTri

from .problem import LayerProblem

FloatArray = NDArray[np.float64]

BASE_SPACING = 0.25
"""Spacing of the tensor grid at the origin (units of R)."""
GROWTH = 1.3
"""Ratio of neighbouring spacings of the tensor grid away from the origin."""
CONTACT_ZONE = 1.4
"""Radius (units of R) about the origin inside which the mesh is graded."""
INCLUSION_SIZE = 0.1
"""Largest triangle at an on-axis inclusion's boundary, over its radius."""
_MAX_REFINEMENTS = 30


@dataclass(frozen=True)
class LayerMesh:
    """A triangulated layer ``[0, radius] x [-thickness, 0]`` (units of R) and its extent."""

    mesh: MeshTri
    thickness: float
    radius: float


def graded_axis(length: float, first: float, growth: float) -> FloatArray:
    """Nodes 0 = x_0 < ... < x_n = length with x_1 = first (capped) and spacings growing by
    ``growth``; the last spacing is merged into the previous one when it would be a sliver."""
    nodes = [0.0]
    step = min(first, length)
    while nodes[-1] + step < length:
        nodes.append(nodes[-1] + step)
        step *= growth
    if len(nodes) > 1 and length - nodes[-1] < 0.5 * (nodes[-1] - nodes[-2]):
        nodes.pop()
    nodes.append(length)
    return np.asarray(nodes)


def build_mesh(problem: LayerProblem) -> LayerMesh:
    """The graded mesh for ``problem`` (units of R)."""
    h = problem.thickness_ratio
    width = problem.radius_ratio
    first = min(BASE_SPACING, h / 4.0)
    r = graded_axis(width, first, GROWTH)
    z = -graded_axis(h, first, GROWTH)[::-1]
    mesh = MeshTri.init_tensor(r, z)
    target = 1.0 / problem.resolution
    floor = target * math.sqrt(problem.depths()[0])
    for _ in range(_MAX_REFINEMENTS):
        marked = _too_large(mesh, target, floor, problem.inclusion)
        if marked.size == 0:
            break
        mesh = mesh.refined(marked)
    else:
        raise RuntimeError("mesh grading did not finish: too many refinement passes")
    return LayerMesh(mesh=mesh, thickness=h, radius=width)


def _too_large(
    mesh: MeshTri, target: float, floor: float, inclusion: tuple[float, float, float, float] | None
) -> NDArray[np.int64]:
    """Indices of triangles in the contact zone larger than ``max(floor, target * distance)``,
    and of triangles near an inclusion's boundary larger than ``radius * INCLUSION_SIZE``."""
    p = mesh.p[:, mesh.t]  # (2, 3, nel)
    centroid = p.mean(axis=1)
    distance = np.hypot(centroid[0], centroid[1])
    edges = p - np.roll(p, 1, axis=1)
    size = np.sqrt((edges**2).sum(axis=0)).max(axis=0)
    near = distance < CONTACT_ZONE
    marked = near & (size > np.maximum(floor, target * distance))
    if inclusion is not None:
        depth, radius = inclusion[0], inclusion[1]
        rho = np.hypot(centroid[0], centroid[1] + depth)
        marked |= (np.abs(rho - radius) < size) & (size > INCLUSION_SIZE * radius)
    return np.flatnonzero(marked)
