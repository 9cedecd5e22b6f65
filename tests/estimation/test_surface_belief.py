"""A convex sample's normal from one tube's touches and a believed radius (issue 25): the touches
of one tube lie on its ray cone, which a plane fits while tilted across the cone; a sphere of
the believed radius gives the normal, and a believed range widens its doubt."""

from __future__ import annotations

import math

import numpy as np
import pytest

from palpate.estimation.pose.surface import fit_plane
from palpate.estimation.pose.surface_belief import fit_sphere_of_radius, sphere_of_radius

APEX_TO_CONTACT = 66e-3  # m, as on this robot's tubes (docs/orientation.md)
SIGMA = 3e-6  # m, a touch's noise along its ray


def cone_touches(
    tube_deg: float, radius: float, span_deg: float, seed: int = 0
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Touches (N, 3), rays (N, 3) and the sphere's centre: a tube's rays at rolls within
    +-span about the one through the centre of a sphere of ``radius`` (m), each touch moved by
    SIGMA noise along its ray."""
    a = math.radians(tube_deg)
    rolls = np.radians(np.linspace(-span_deg, span_deg, 4))
    rays = np.stack([np.full(4, math.cos(a)), math.sin(a) * np.cos(rolls),
                     math.sin(a) * np.sin(rolls)], axis=1)  # fmt: skip
    centre = np.array([math.cos(a), math.sin(a), 0.0]) * (APEX_TO_CONTACT + radius)
    b = rays @ centre
    t = b - np.sqrt(b * b - (float(centre @ centre) - radius**2))
    t = t + np.random.default_rng(seed).normal(0.0, SIGMA, t.size)
    return t[:, None] * rays, rays, centre


def angle(u: np.ndarray, v: np.ndarray) -> float:
    return math.degrees(math.acos(float(np.clip(u @ v, -1.0, 1.0))))


@pytest.mark.parametrize("tube_deg", [15.0, 30.0, 50.0])
@pytest.mark.parametrize("radius", [30e-3, 100e-3])
def test_the_believed_radius_gives_the_normal_a_plane_misses(
    tube_deg: float, radius: float
) -> None:
    p, rays, centre = cone_touches(tube_deg, radius, 20.0)
    kwargs = {"sigma": SIGMA, "hint": -rays.mean(axis=0), "directions": rays, "reference": p[0]}
    fit = fit_sphere_of_radius(p, (radius, radius), **kwargs)
    assert fit.success, fit.message
    assert fit.centres is not None
    truth = (p[0] - centre) / np.linalg.norm(p[0] - centre)
    error = angle(fit.centres.normal_at(p[0]), truth)
    assert error < max(3.0 * math.degrees(fit.normal_sigma), 0.1)
    assert error < 0.3
    assert fit.free_parameters == 3
    plane = fit_plane(p, **kwargs)
    assert plane.centres is not None
    assert angle(plane.centres.normal, truth) > 8.0  # the cone's curve is nearly flat


def test_a_believed_range_widens_the_normals_doubt_by_what_it_leaves_open() -> None:
    p, rays, _ = cone_touches(30.0, 60e-3, 20.0)
    kwargs = {"sigma": SIGMA, "hint": -rays.mean(axis=0), "directions": rays, "reference": p[0]}
    exact = fit_sphere_of_radius(p, (60e-3, 60e-3), **kwargs)
    ranged = fit_sphere_of_radius(p, (54e-3, 66e-3), **kwargs)
    assert ranged.success
    assert ranged.normal_sigma > 5.0 * exact.normal_sigma
    assert "range turns the normal by" in ranged.message


def test_bad_radii_are_refused_and_collinear_touches_fail_with_a_message() -> None:
    with pytest.raises(ValueError, match="radii"):
        fit_sphere_of_radius(np.eye(3), (2.0, 1.0), sigma=SIGMA, hint=(1, 0, 0))
    with pytest.raises(ValueError, match="radius"):
        sphere_of_radius(0.0)
    line = np.array([[0.0, 0.0, 0.0], [1e-3, 0.0, 0.0], [2e-3, 0.0, 0.0], [3e-3, 0.0, 0.0]])
    fit = fit_sphere_of_radius(line, (0.03, 0.03), sigma=SIGMA, hint=(0, 0, 1))
    assert not fit.success
    assert "no sphere of the believed radius" in fit.message
