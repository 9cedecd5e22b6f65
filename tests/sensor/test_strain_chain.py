"""Wavelength -> strain (Eq. 1): baseline, the three temperature modes, grating geometry."""

from __future__ import annotations

import numpy as np
import pytest

from palpate.config.schema import FbgConfig, SensorConfig
from palpate.estimation.beam.section import grating_intervals
from palpate.sensor.strain import (
    StrainChain,
    capture_baseline,
    strain_noise,
    wavelength_to_strain,
)

BASE = np.array([1530e-9, 1535e-9, 1540e-9])
K = 0.424e-12 / 1e-6  # m per unit strain
S_T = 10e-12  # m/K


def rest(n: int = 10, ref: bool = False) -> tuple[np.ndarray, np.ndarray | None]:
    w = np.tile(BASE, (n, 1))
    return w, (np.full(n, 1550e-9) if ref else None)


def test_known_shift_gives_known_strain() -> None:
    base = capture_baseline(rest()[0])
    eps = np.array([100e-6, -50e-6, 0.0])
    w = BASE + K * eps
    np.testing.assert_allclose(wavelength_to_strain(w, base, k_eps=K), eps, atol=1e-12)


def test_measured_temperature_is_removed() -> None:
    base = capture_baseline(rest()[0])
    eps = np.array([[10e-6, 20e-6, 30e-6], [0.0, 0.0, 0.0]])
    dT = np.array([2.0, -1.0])
    w = BASE + K * eps + S_T * dT[:, None]
    out = wavelength_to_strain(w, base, k_eps=K, mode="measured", delta_t=dT)
    np.testing.assert_allclose(out, eps, atol=1e-12)
    # The paper's dT = 0 would read 2 K as 47 ue of strain.
    naive = wavelength_to_strain(w, base, k_eps=K)
    assert naive[0, 0] - eps[0, 0] == pytest.approx(S_T * 2 / K)


def test_reference_grating_compensates_temperature() -> None:
    w0, r0 = rest(ref=True)
    chain = StrainChain(K, S_T, "reference").zeroed(w0, r0)
    eps = np.array([5e-6, -5e-6, 50e-6])
    dT = 1.5
    out = chain.strains(BASE + K * eps + S_T * dT, reference=1550e-9 + S_T * dT)
    np.testing.assert_allclose(out, eps, atol=1e-12)


def test_from_config_and_noise() -> None:
    chain = StrainChain.from_config(FbgConfig())
    assert chain.k_eps == pytest.approx(K)
    assert chain.mode == "none"
    rng = np.random.default_rng(0)
    w = BASE + rng.normal(0, 1e-12, size=(4000, 3))
    zeroed = chain.zeroed(w)
    np.testing.assert_allclose(zeroed.strain_noise(), strain_noise(1.0), rtol=0.05)
    assert strain_noise(0.424) == pytest.approx(1e-6)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"mode": "measured"}, "delta_t"),
        ({"mode": "reference"}, "reference"),
        ({"mode": "bogus"}, "unknown temperature mode"),
        ({"k_eps": 0.0}, "k_eps"),
    ],
)
def test_mode_errors(kwargs: dict[str, object], match: str) -> None:
    base = capture_baseline(rest()[0])
    args: dict[str, object] = {"k_eps": K, **kwargs}
    with pytest.raises(ValueError, match=match):
        wavelength_to_strain(BASE, base, **args)  # type: ignore[arg-type]


def test_baseline_errors() -> None:
    with pytest.raises(ValueError, match="shape"):
        capture_baseline(BASE)
    with pytest.raises(ValueError, match="non-finite"):
        capture_baseline([[np.nan, 1.0]])
    with pytest.raises(ValueError, match="reference has"):
        capture_baseline(rest()[0], np.zeros(3))
    with pytest.raises(ValueError, match="baseline"):
        StrainChain(K, S_T, "none").strains(BASE)
    with pytest.raises(ValueError, match="wavelengths end in"):
        wavelength_to_strain(BASE[:2], capture_baseline(rest()[0]), k_eps=K)


def test_grating_intervals_follow_the_config() -> None:
    iv = grating_intervals(SensorConfig())
    # L = 42 mm; centres 10, 18, 26 mm from the tip; 3 mm gratings.
    np.testing.assert_allclose(iv * 1e3, [[30.5, 33.5], [22.5, 25.5], [14.5, 17.5]])
    np.testing.assert_allclose(grating_intervals(SensorConfig(), 0.05)[0] * 1e3, [38.5, 41.5])
