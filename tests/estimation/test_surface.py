"""Surface geometry and its fits to touched points (estimation.pose.surface)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from palpate.estimation.pose.surface import (
    SurfaceGeometry,
    fit_plane,
    fit_sphere,
    fit_surface,
    load_crossing,
)


def _rays_to(surface: SurfaceGeometry, apex: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """Where rays from ``apex`` meet ``surface`` (N, 3)."""
    hits = [apex + surface.ray_hit(apex, d) * d for d in directions]
    return np.array(hits)


def _fan(n: int, spread_deg: float) -> np.ndarray:
    """Unit directions on a cone about -z, half-angle 20 deg, over +-spread of azimuth."""
    az = np.radians(np.linspace(-spread_deg, spread_deg, n))
    a = math.radians(20.0)
    return np.stack([np.sin(a) * np.cos(az), np.sin(a) * np.sin(az), -np.cos(a) * np.ones(n)], -1)


def test_ray_hit_plane_and_sphere() -> None:
    plane = SurfaceGeometry.make((0, 0, -0.05), (0, 0, 1))
    assert plane.ray_hit(np.zeros(3), np.array([0, 0, -1.0])) == pytest.approx(0.05)
    assert plane.ray_hit(np.zeros(3), np.array([0, 0, 1.0])) == math.inf  # runs away
    sphere = SurfaceGeometry.make((0, 0, -0.05), (0, 0, 1), radius=0.02)
    assert sphere.ray_hit(np.zeros(3), np.array([0, 0, -1.0])) == pytest.approx(0.05)
    assert sphere.ray_hit(np.array([0.1, 0, 0]), np.array([0, 0, -1.0])) == math.inf  # misses
    assert sphere.offset(0.003).ray_hit(np.zeros(3), np.array([0, 0, -1.0])) == pytest.approx(0.047)
    with pytest.raises(ValueError, match="inside out"):
        sphere.offset(-0.03)


def test_plane_fit_from_noisy_touches_finds_the_normal_within_its_sigma() -> None:
    rng = np.random.default_rng(7)
    truth = SurfaceGeometry.make((0.0, 0.0, -0.06), (0.2, -0.1, 1.0))
    apex = np.zeros(3)
    rays = _fan(4, 40.0)
    sigma = 10e-6
    errors, sigmas = [], []
    for _ in range(200):
        pts = _rays_to(truth, apex, rays) + rng.normal(0, sigma, (4, 1)) * rays
        fit = fit_plane(pts, sigma=sigma, hint=(0, 0, 1), directions=rays)
        assert fit.success
        assert fit.centres is not None
        errors.append(math.acos(min(1.0, float(fit.centres.normal @ truth.normal))))
        sigmas.append(fit.normal_sigma)
    # the propagated 1-sigma angle is the rms error (to sampling noise)
    rms = math.sqrt(float(np.mean(np.square(errors))))
    assert 0.7 < rms / float(np.median(sigmas)) < 1.4
    assert rms < math.radians(0.5)


def test_plane_fit_reports_collinear_touches() -> None:
    pts = np.array([[0, 0, 0], [1e-3, 0, 0], [2e-3, 0, 0.0]])
    fit = fit_plane(pts, sigma=1e-5, hint=(0, 0, 1))
    assert not fit.success
    assert "collinear" in fit.message
    with pytest.raises(ValueError, match="no surface"):
        fit.surface(3.5e-3)


def test_sphere_fit_recovers_centre_and_radius_and_moves_in_by_the_tip() -> None:
    rng = np.random.default_rng(3)
    truth = SurfaceGeometry.make((0.01, 0.0, -0.05), (0.0, 0.3, 1.0), radius=0.04)
    offset = truth.offset(3.5e-3)  # the tip centres lie on this
    dirs = rng.normal(size=(12, 3))
    dirs[:, 2] = np.abs(dirs[:, 2]) + 2.0  # a cap facing the robot
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    pts = offset.centre + offset.radius * dirs + rng.normal(0, 5e-6, (12, 3))
    fit = fit_sphere(pts, sigma=5e-6, hint=(0, 0, 1))
    assert fit.success
    assert fit.model == "sphere"
    surface = fit.surface(3.5e-3)
    assert surface.radius == pytest.approx(0.04, abs=2e-5)
    assert np.allclose(surface.centre, truth.centre, atol=2e-5)


def test_fit_surface_takes_the_sphere_only_when_the_plane_cannot_explain_the_touches() -> None:
    rng = np.random.default_rng(11)
    apex = np.array([0.02, 0.0, 0.03])  # off the sphere's axis: the touches are not coplanar
    rays = _fan(7, 60.0)
    sphere = SurfaceGeometry.make((0, 0, -0.05), (0, 0, 1), radius=0.08)
    curved = _rays_to(sphere, apex, rays) + rng.normal(0, 5e-6, (7, 1)) * rays
    assert fit_surface(curved, sigma=5e-6, hint=(0, 0, 1), directions=rays).model == "sphere"
    plane = SurfaceGeometry.make((0, 0, -0.05), (0.1, 0, 1))
    flat = _rays_to(plane, apex, rays) + rng.normal(0, 5e-6, (7, 1)) * rays
    assert fit_surface(flat, sigma=5e-6, hint=(0, 0, 1), directions=rays).model == "plane"


def test_load_crossing_finds_the_threshold_of_a_noisy_hertz_ramp() -> None:
    rng = np.random.default_rng(5)
    x0, depth, threshold = 0.042, 400e-6, 25e-6
    c = threshold / depth**1.5
    errs = []
    for _ in range(100):
        x = np.arange(0.0405, x0 + 2 ** (2 / 3) * depth, 20e-6)
        load = 3e-6 + c * np.clip(x - x0, 0, None) ** 1.5 + rng.normal(0, 5e-6, x.size)
        found = load_crossing(x, load, threshold)
        assert found is not None
        start, crossing = found
        assert abs(start - x0) < 200e-6  # the toe of the power law is the loose end
        errs.append(crossing - (x0 + depth))
    assert abs(float(np.mean(errs))) < 5e-6
    assert float(np.std(errs)) < 15e-6


def test_load_crossing_of_a_flat_record_and_bad_input() -> None:
    x = np.linspace(0, 1e-3, 20)
    assert load_crossing(x, np.zeros(20) - 1e-6 * x, 25e-6) is None
    with pytest.raises(ValueError, match="threshold"):
        load_crossing(x, np.zeros(20), 0.0)
