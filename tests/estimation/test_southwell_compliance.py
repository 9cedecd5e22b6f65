"""The beam's bow (Southwell) and the rig's compliance (rigid reference) on synthetic records."""

from __future__ import annotations

import math

import numpy as np
import pytest

from palpate.estimation.beam.elastica.constants import MODE_SHORTENING
from palpate.estimation.fits.compliance import ComplianceFit, fit_compliance, pooled
from palpate.estimation.fits.southwell import southwell

L = 42e-3
P_CR = 1.35


def bowed(w0_over_l: float, p_cr: float, rng: np.random.Generator, noise: float = 0.0):  # type: ignore[no-untyped-def]
    """Loads rising to 0.95 P_cr and the signed amplitudes z the strains give for a beam bowed
    w0: a = w0 (P/P_cr)/(1 - P/P_cr), z = a sqrt(c) / L."""
    P = np.linspace(0.0, 0.95 * p_cr, 400)
    a = w0_over_l * L * (P / p_cr) / (1.0 - P / p_cr)
    z = a * math.sqrt(MODE_SHORTENING) / L
    return P, z + rng.normal(0.0, noise, P.size)


def test_southwell_recovers_the_bow_and_the_critical_load() -> None:
    rng = np.random.default_rng(0)
    P, z = bowed(0.004, 1.2, rng, noise=2e-5)
    fit = southwell(P, z, L, P_CR)  # the model's P_cr only sets the load window
    assert fit.success
    assert fit.w0_over_l == pytest.approx(0.004, rel=0.05)
    assert fit.critical_load == pytest.approx(1.2, rel=0.02)


def test_southwell_fails_explicitly_without_a_pre_buckling_record() -> None:
    fit = southwell(np.linspace(0, 0.1, 50), np.zeros(50), L, P_CR)
    assert not fit.success
    assert "too few pre-buckling samples" in fit.message
    with pytest.raises(ValueError, match="finite"):
        southwell([0.0, math.nan], [0.0, 0.0], L, P_CR)


def rigid_record(c: float, rng: np.random.Generator, n: int = 2000):  # type: ignore[no-untyped-def]
    """A rigid reference: u - x0 = e + c P; the load rises to P_CR, then the beam shortens."""
    x0 = 30e-3
    u = np.linspace(x0 - 0.5e-3, x0 + 1.0e-3, n)
    w = np.clip(u - x0, 0.0, None)
    ea = 9.7e3
    P = np.minimum(w / (c + L / ea), P_CR)
    e = np.where(P < P_CR, P * L / ea, w - c * P_CR)
    return u, P + rng.normal(0.0, 0.01, n), e


@pytest.mark.parametrize("c", [2e-5, 1e-4])
def test_the_compliance_is_the_slope_of_u_minus_e_against_the_load(c: float) -> None:
    rng = np.random.default_rng(1)
    fit = fit_compliance(*rigid_record(c, rng))
    assert fit.success
    assert fit.message == "ok"
    assert fit.compliance == pytest.approx(c, rel=0.03)
    assert fit.ci_high is not None
    assert fit.ci_low is not None
    assert 0 < fit.ci_high - fit.ci_low < 0.1 * c


def test_a_stiff_rig_is_bounded_by_the_advance_its_load_rose_over() -> None:
    rng = np.random.default_rng(1)
    fit = fit_compliance(*rigid_record(0.0, rng))
    assert fit.success
    assert "stiff" in fit.message
    assert fit.ci_low == 0.0
    assert fit.ci_high is not None
    assert 0 < fit.ci_high < 1e-5  # 0.01 mm/N: a few samples' advance over P_cr


def test_no_load_is_no_calibration_and_pooled_takes_the_envelope() -> None:
    assert not fit_compliance(np.arange(30.0), np.zeros(30), np.zeros(30)).success
    fits = [
        ComplianceFit(True, "ok", 1e-4, 0.9e-4, 1.1e-4),
        ComplianceFit(True, "ok", 1.05e-4, 1.0e-4, 1.2e-4),
        ComplianceFit(False, "no contact"),
    ]
    assert pooled(fits) == (0.9e-4, 1.2e-4)
    assert pooled([ComplianceFit(True, "ok", 0.0, -1e-6, 1e-6)]) == (0.0, 1e-6)
    assert pooled([]) is None


def test_a_known_compliance_in_series_comes_out_of_the_fit_and_its_interval() -> None:
    from palpate.estimation.fits.compliance import ComplianceFit, less

    fit = ComplianceFit(True, "ok", 1e-4, 0.9e-4, 1.1e-4, 0.01, 50)
    tube = less(fit, 2e-5)  # a tip grating's element, 0.02 mm/N
    assert tube.compliance == pytest.approx(8e-5)
    assert (tube.ci_low, tube.ci_high) == (pytest.approx(7e-5), pytest.approx(9e-5))
    assert tube.contact == fit.contact
    assert less(fit, 0.0) is fit
    failed = ComplianceFit(False, "too few points")
    assert less(failed, 2e-5) == failed
