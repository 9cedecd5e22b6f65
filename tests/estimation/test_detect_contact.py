"""Model-independent contact detectors on synthetic loading records."""

from __future__ import annotations

import numpy as np
import pytest

from palpate.estimation.detect.contact import baseline_deviation, ratio_of_variances

X0 = 1.0e-3


def record(seed: int = 0, loading: bool = True) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    x = np.linspace(0.0, 2e-3, 800)
    force = np.where(x > X0, 2e4 * np.clip(x - X0, 0, None) ** 1.5 * 1e3, 0.0) if loading else 0 * x
    return x, force + rng.normal(0.0, 0.01, x.size)


def test_baseline_deviation_finds_contact_a_little_late() -> None:
    x, f = record()
    g = baseline_deviation(x, f)
    assert g.success
    assert g.position is not None
    # a sphere loads like delta^1.5: the 5-sigma crossing comes after contact, not far after
    assert X0 < g.position < X0 + 0.2e-3
    assert g.baseline_sigma == pytest.approx(0.01, rel=0.3)


def test_ratio_of_variances_peaks_near_contact() -> None:
    x, f = record(1)
    g = ratio_of_variances(x, f, window=40)
    assert g.success
    assert g.position is not None
    assert abs(g.position - X0) < 0.25e-3


def test_no_contact_is_said_not_guessed() -> None:
    x, f = record(2, loading=False)
    for g in (baseline_deviation(x, f), ratio_of_variances(x, f)):
        assert not g.success
        assert g.position is None
        assert "no contact" in g.message


def test_bad_input() -> None:
    with pytest.raises(ValueError, match="one length"):
        baseline_deviation(np.zeros(50), np.zeros(49))
    with pytest.raises(ValueError, match="at least"):
        baseline_deviation(np.zeros(10), np.zeros(10))
    with pytest.raises(ValueError, match="finite"):
        ratio_of_variances(np.zeros(100), np.full(100, np.nan))
