"""The misalignment of a slipping contact from the tip's path (issue 25): a record made from a
clamped beam-column sliding on a Hertz contact, integrated here by quadrature, gives back its
angle within the stated uncertainty whatever the friction; the bow's closed form; the refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest

from palpate.estimation.pose.slip_path import bow_shortening, measure_slip_path

EI, EA, DY, L = 1.18e-4, 9.7e3, 1.53e-4, 42e-3  # the paper's sensor (N m^2, N, m, m)
FROM_TIP = np.array([[16.5e-3, 19.5e-3], [24.5e-3, 27.5e-3], [32.5e-3, 35.5e-3]])
E_STAR, R_TIP = 395e3, 3.5e-3  # Pa (315 kPa at nu 0.45), m
NOISE_UE, NOISE_M = 1.0e-6, 0.5e-6  # the gratings' and the encoder's


def record(
    psi_deg: float, friction: float, seed: int = 0, side: float = 1.0
) -> tuple[np.ndarray, ...]:
    """(strains (N, 3), advances (N,), lengths (N,)) of a tip sliding on a surface psi off its
    axis, toward ``side`` of the fiber's plane: the load leans gamma = psi - atan(mu), the tip
    deflects and the normal depth follows the load (Hertz); slopes and grating means by
    quadrature."""
    psi = math.radians(psi_deg)
    lean = math.tan(psi - math.atan(friction))
    cap = (math.pi / 2) ** 2 * EI / L**2
    P = cap * np.linspace(0.02, 0.9, 120)
    k = np.sqrt(P / EI)
    s = np.linspace(0.0, L, 801)  # from the clamp
    slope = lean * (np.cos(k[:, None] * (L - s)) - np.cos(k * L)[:, None]) / np.cos(k * L)[:, None]
    w = np.trapezoid(slope, s, axis=1)
    bow = 0.5 * np.trapezoid(slope**2, s, axis=1)
    strains = np.empty((P.size, 3))
    for g, (d0, d1) in enumerate(FROM_TIP):
        d = np.linspace(d0, d1, 61)
        kappa = lean * k[:, None] * np.sin(k[:, None] * d) / np.cos(k * L)[:, None]
        strains[:, g] = -side * DY * kappa.mean(axis=1) - P / EA
    normal = P / (math.cos(psi) + friction * math.sin(psi))
    depth = (3.0 * normal / (4.0 * E_STAR * math.sqrt(R_TIP))) ** (2.0 / 3.0)
    advance = 41.9e-3 + P * L / EA + bow + depth / math.cos(psi) + w * math.tan(psi)
    rng = np.random.default_rng(seed)
    strains = strains + rng.normal(0.0, NOISE_UE, strains.shape)
    advance = advance + rng.normal(0.0, NOISE_M, advance.shape)
    return strains, advance, np.full(P.size, L)


@pytest.mark.parametrize(("psi_deg", "friction"), [(3.0, 0.02), (8.0, 0.05), (12.0, 0.2),
                                                   (20.0, 0.05), (20.0, 0.3)])  # fmt: skip
def test_the_angle_comes_back_within_its_uncertainty_whatever_the_friction(
    psi_deg: float, friction: float
) -> None:
    strains, advance, lengths = record(psi_deg, friction)
    path = measure_slip_path(strains, advance, lengths, FROM_TIP, EA, EI, DY)
    assert path.success, path.message
    error = abs(math.degrees(path.angle) - psi_deg)
    assert error < 3.0 * math.degrees(path.sigma)
    assert error < 1.0
    assert path.side == 1.0


def test_the_side_is_the_slides() -> None:
    strains, advance, lengths = record(10.0, 0.05, side=-1.0)
    path = measure_slip_path(strains, advance, lengths, FROM_TIP, EA, EI, DY)
    assert path.success
    assert path.side == -1.0
    assert math.degrees(path.angle) == pytest.approx(10.0, abs=1.0)


@pytest.mark.parametrize("kl", [1e-5, 0.3, 1.0, 1.5])
def test_the_bows_closed_form_is_the_integral_of_the_slope_squared(kl: float) -> None:
    s = np.linspace(0.0, L, 4001)
    k = kl / L
    slope = 0.1 * (np.cos(k * (L - s)) - math.cos(kl)) / math.cos(kl)
    quad = 0.5 * np.trapezoid(slope**2, s)
    closed = float(bow_shortening(0.1, np.array([kl]), np.array([L]))[0])
    assert closed == pytest.approx(quad, rel=1e-5, abs=1e-18)


def test_too_few_bent_rows_and_bad_shapes_are_said() -> None:
    strains, advance, lengths = record(10.0, 0.05)
    few = measure_slip_path(strains[:5], advance[:5], lengths[:5], FROM_TIP, EA, EI, DY)
    assert not few.success
    assert "the path's fit needs" in few.message
    with pytest.raises(ValueError, match="strains"):
        measure_slip_path(strains, advance[:3], lengths, FROM_TIP, EA, EI, DY)
