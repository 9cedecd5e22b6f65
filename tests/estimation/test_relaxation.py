"""The relaxation fit on seeded records of both relaxation forms, an elastic record, an
unfinished relaxation and bad input (``estimation.relaxation``)."""

from __future__ import annotations

import numpy as np
import pytest

from palpate.estimation.contact.law import ContactLaw
from palpate.estimation.relaxation import RelaxationRecord, fit_relaxation, memory_basis
from palpate.sim.viscoelastic import PowerLawSolid, Relaxation, StandardLinearSolid, force_history

LAW = ContactLaw(2e-3, 0.45, 10e-3, True)
E_INF = 400e3
SIGMA = 0.004  # N
DT = 4e-3


class Elastic:
    def __init__(self, modulus: float) -> None:
        self.modulus = modulus

    def force_and_stiffness_at(self, delta: float) -> tuple[float, float]:
        f, df = LAW.shape(np.array([delta]))
        return float(self.modulus * f[0]), float(self.modulus * df[0])


def record(relax: Relaxation, speed: float, hold: float, seed: int = 0) -> RelaxationRecord:
    """A ramp to 0.6 mm at ``speed`` (m/s) from 0.2 mm before contact, then ``hold`` s at rest
    (the depth known: contact at 0), the load with white noise."""
    t = np.arange(0.0, 0.8e-3 / speed + hold, DT)
    u = np.minimum(t * speed, 0.8e-3) - 0.2e-3
    force = force_history(relax, Elastic(E_INF / relax.ratio), t, np.maximum(u, 0.0))
    noisy = force + np.random.default_rng(seed).normal(0.0, SIGMA, t.size)
    n = t.size
    return RelaxationRecord(t, noisy, u, np.full(n, SIGMA), np.full(n, 1e-7), hold)


def fit(rec: RelaxationRecord):  # type: ignore[no-untyped-def]
    return fit_relaxation(rec, LAW, (-20e-6, 0.0, 20e-6), E_INF)


@pytest.mark.parametrize(
    "relax",
    [StandardLinearSolid(0.5, 0.6), PowerLawSolid(0.1, 0.6, 1.0)],
    ids=["sls", "power-law"],
)
@pytest.mark.parametrize("speed", [0.1e-3, 2e-3])
def test_the_relaxed_modulus_of_a_seeded_record(relax: Relaxation, speed: float) -> None:
    result = fit(record(relax, speed, hold=8.0))
    assert result.success, result.message
    assert result.relaxes
    assert result.complete, result.warnings
    assert result.covers(E_INF)
    assert result.relaxed == pytest.approx(E_INF, rel=0.03)
    assert result.instantaneous is not None
    assert result.instantaneous > 1.1 * E_INF


def test_a_fast_indentation_reads_the_instantaneous_modulus_too() -> None:
    relax = StandardLinearSolid(1.0, 0.6)
    result = fit(record(relax, 2e-3, hold=8.0))
    e0 = E_INF / relax.ratio
    assert result.instantaneous_low is not None
    assert result.instantaneous_high is not None
    assert result.instantaneous == pytest.approx(e0, rel=0.05)
    assert result.relaxation_time == pytest.approx(1.0, rel=0.5)


def test_an_elastic_record_shows_no_relaxation() -> None:
    for seed in range(3):
        result = fit(record(StandardLinearSolid(1.0, 1.0), 0.5e-3, hold=5.0, seed=seed))
        assert result.success
        assert not result.relaxes, result.delta_chi2
        assert result.covers(E_INF)
        assert "no relaxation" in result.summary()


def test_a_relaxation_slower_than_the_hold_is_said_to_be_extrapolated() -> None:
    result = fit(record(PowerLawSolid(0.5, 0.5, 0.3), 0.5e-3, hold=2.0))
    assert result.success
    assert result.relaxes
    assert not result.complete
    assert any("not complete" in w for w in result.warnings)


def test_a_record_without_a_hold_has_no_relaxation_fit() -> None:
    rec = record(StandardLinearSolid(0.5, 0.6), 0.5e-3, hold=0.0)
    result = fit(rec)
    assert not result.success
    assert "no hold" in result.message


def test_bad_input_is_refused() -> None:
    rec = record(StandardLinearSolid(0.5, 0.6), 0.5e-3, hold=1.0)
    with pytest.raises(ValueError, match="contact"):
        fit_relaxation(rec, LAW, (1e-5, 0.0, -1e-5), E_INF)
    bad = RelaxationRecord(rec.times[::-1], rec.load, rec.depth_base, rec.sigma_load,
                           rec.sigma_depth, 1.0)  # fmt: skip
    with pytest.raises(ValueError, match="increase"):
        fit_relaxation(bad, LAW, (-1e-5, 0.0, 1e-5), E_INF)


def test_the_memory_basis_on_a_jittered_clock_is_the_same_recursion() -> None:
    rng = np.random.default_rng(1)
    t = np.cumsum(rng.uniform(3e-3, 5e-3, 400))
    shape = np.sin(t) ** 2
    taus = np.array([0.01, 0.1, 1.0])
    jittered = memory_basis(t, shape, taus)
    uniform_t = np.arange(400) * 4e-3
    lfiltered = memory_basis(uniform_t, shape, taus)
    manual = np.zeros_like(lfiltered)
    for k, tau in enumerate(taus):
        h, prev = 0.0, 0.0
        for i in range(t.size):
            dt = t[i] - t[i - 1] if i else 0.0
            x = dt / tau
            gain = -np.expm1(-x) / x if x > 0 else 1.0
            h = np.exp(-x) * h + gain * (shape[i] - prev)
            prev = shape[i]
            manual[i, k] = h
    np.testing.assert_allclose(jittered, manual, rtol=1e-12, atol=1e-15)
    assert lfiltered.shape == manual.shape
    assert np.all(np.isfinite(lfiltered))
