"""Buckling detectors on synthetic signals with a known onset, and the first-mode test problem."""

from __future__ import annotations

import numpy as np
import pytest

from palpate.config.schema import SensorConfig
from palpate.estimation.beam.elastica.constants import MODE_SLOPE_INTEGRAL, X1
from palpate.estimation.beam.section import grating_intervals
from palpate.estimation.detect.buckling import (
    CusumDetector,
    NormThreshold,
    cusum,
    first_mode_pattern,
    first_mode_strains,
)
from palpate.sensor.strain import strain_noise

L = 0.042
DY = 0.153e-3
IV = grating_intervals(SensorConfig())


def test_beta_is_the_clamped_pinned_root() -> None:
    assert np.tan(X1) == pytest.approx(X1, rel=1e-9)
    assert pytest.approx(20.19, abs=0.005) == X1**2


def test_mode_pattern_matches_quadrature_of_the_curvature() -> None:
    def curvature(xi: np.ndarray) -> np.ndarray:
        return X1 * (X1 * np.cos(X1 * xi) - np.sin(X1 * xi))

    for s0, s1 in IV:
        xi = np.linspace(s0 / L, s1 / L, 2001)
        expected = np.trapezoid(curvature(xi), xi) / (xi[-1] - xi[0])
        assert first_mode_pattern([[s0, s1]], L)[0] == pytest.approx(expected, rel=1e-6)


def test_mode_energy_integral_and_sqrt_growth() -> None:
    xi = np.linspace(0, 1, 200001)
    g = (np.cos(X1 * xi) + X1 * np.sin(X1 * xi) - 1) ** 2
    assert pytest.approx(np.trapezoid(g, xi), rel=1e-8) == MODE_SLOPE_INTEGRAL
    e = np.array([1e-4, 4e-4])
    s = first_mode_strains(e, IV, L, DY)
    np.testing.assert_allclose(s[1] / s[0], 2.0)  # strain ~ sqrt(e/L)
    assert np.all(first_mode_strains(0.0, IV, L, DY) == 0)
    with pytest.raises(ValueError, match=">= 0"):
        first_mode_strains(-1e-3, IV, L, DY)


def signal(
    rng: np.random.Generator, sigma: float, onset: int, n: int, axial: float = 0.0
) -> np.ndarray:
    """Strains (n, 3): noise, a common-mode ramp to ``axial`` before onset, then sqrt growth."""
    u = np.arange(n) - onset
    e = np.clip(u, 0, None) * 0.5e-6 / L
    ramp = np.clip((np.arange(n) + 1) / onset, 0, 1)[:, None] * axial
    return ramp + first_mode_strains(e, IV, L, DY) + rng.normal(0, sigma, size=(n, 3))


@pytest.mark.parametrize("noise_pm", [0.5, 1.0, 3.0])
def test_detectors_fire_after_a_known_onset(noise_pm: float) -> None:
    rng = np.random.default_rng(7)
    sigma = strain_noise(noise_pm)
    onset = 500
    s = signal(rng, sigma, onset, 700)
    pattern = first_mode_pattern(IV, L)
    for det in (
        NormThreshold(10 * sigma * np.sqrt(3)),
        CusumDetector(sigma, pattern=pattern),
        CusumDetector(sigma),
    ):
        idx = det.first_alarm(s)
        assert idx is not None
        assert onset <= idx <= onset + 20, type(det).__name__


def test_streaming_equals_vectorised() -> None:
    rng = np.random.default_rng(3)
    sigma = strain_noise(1.0)
    s = signal(rng, sigma, 300, 400)
    for det in (
        NormThreshold(30e-6),
        CusumDetector(sigma, pattern=first_mode_pattern(IV, L)),
        CusumDetector(sigma),
    ):
        idx = det.first_alarm(s)
        det.reset()
        streamed = next(i for i, row in enumerate(s) if det.update(row))
        assert streamed == idx
        assert det.alarm


def test_axial_preload_fools_the_norm_rule_not_the_cusum() -> None:
    rng = np.random.default_rng(11)
    sigma = strain_noise(1.0)
    onset = 1000
    s = signal(rng, sigma, onset, 1200, axial=-140e-6)
    norm_idx = NormThreshold(100e-6).first_alarm(s)
    assert norm_idx is not None
    assert norm_idx < onset
    for det in (CusumDetector(sigma, pattern=first_mode_pattern(IV, L)), CusumDetector(sigma)):
        idx = det.first_alarm(s)
        assert idx is not None
        assert onset <= idx <= onset + 20


def test_no_false_alarm_on_long_noise() -> None:
    rng = np.random.default_rng(5)
    sigma = strain_noise(3.0)
    noise = rng.normal(0, sigma, size=(200_000, 3))
    assert CusumDetector(sigma, pattern=first_mode_pattern(IV, L)).first_alarm(noise) is None
    assert CusumDetector(sigma).first_alarm(noise) is None


def test_cusum_path_equals_the_recursion() -> None:
    x = np.random.default_rng(0).normal(size=500)
    s, expected = 0.0, []
    for v in x:
        s = max(0.0, s + v)
        expected.append(s)
    np.testing.assert_allclose(cusum(x), expected, atol=1e-12)


def test_detector_errors() -> None:
    with pytest.raises(ValueError, match="threshold"):
        NormThreshold(0.0)
    with pytest.raises(ValueError, match="sigma"):
        CusumDetector(0.0)
    with pytest.raises(ValueError, match="common-mode"):
        CusumDetector(1e-6, pattern=np.ones(3)).first_alarm(np.zeros((5, 3)))
    with pytest.raises(ValueError, match="shape"):
        NormThreshold(1e-6).first_alarm(np.zeros(5))


def test_first_mode_agrees_with_the_elastica_and_the_strain_fit_inverts_it() -> None:
    """Cross-check against ``estimation.beam.model`` (the full elastica) near onset."""
    beam_mod = pytest.importorskip("palpate.estimation.beam.model")
    from palpate.estimation.fits.strain_fit import fit_strains

    EI, EA = 1.18e-4, 9696.0
    beam = beam_mod.Beam(EI, EA, DY, L)
    e_axial = X1**2 * EI / L**2 / EA  # pre-buckling shortening ratio at P_cr
    e_over_L = 2e-3
    full = np.asarray(beam.grating_strains(e_over_L * L, IV))
    linear = first_mode_strains(e_over_L - e_axial, IV, L, DY)
    np.testing.assert_allclose(np.abs(full), np.abs(linear), rtol=0.02)
    fit = fit_strains(beam, full, IV, sigma=1e-6)
    assert fit.success
    assert fit.e == pytest.approx(e_over_L * L, rel=1e-3)
    p_cr = X1**2 * EI / L**2
    p_fit = float(fit.P)
    assert p_fit == pytest.approx(p_cr, rel=0.01)
