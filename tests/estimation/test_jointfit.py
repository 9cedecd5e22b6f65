"""Joint fit of modulus and contact position on synthetic loading curves (seeded)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from palpate.estimation.contact.law import ContactLaw
from palpate.estimation.jointfit import JointFit, joint_fit
from palpate.estimation.jointfit.grid import closed_form, grid_fits
from palpate.estimation.jointfit.profile import profiles

LAW = ContactLaw(3.5e-3, 0.45, 10e-3, bonded=True, large_indentation=True)
EA = 9.7e3
L = 44e-3
SIGMA_P = 0.03  # N
Q = 20e-3 / 4096  # encoder count


def curve(
    E: float, x0: float, rng: np.random.Generator, n: int = 300, law: ContactLaw = LAW
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Stage advance from 0.8 mm before contact to 0.9 mm after, load capped like a buckling
    beam (the advance beyond goes into shortening), encoder-quantised, load noise SIGMA_P."""
    u = np.round(np.linspace(x0 - 0.8e-3, x0 + 0.9e-3, n) / Q) * Q
    delta = np.clip(u - x0, 0.0, None)
    P = law.force(E, delta)
    cap = float(law.force(E, 0.6e-3))
    over = cap < P
    # past the cap the load stays ~constant and the beam shortens; solve P(delta) = cap there
    delta_cap = 0.6e-3
    e = np.where(over, u - x0 - delta_cap, P * L / EA)
    P = np.where(over, cap, P)
    return u, P + rng.normal(0.0, SIGMA_P, n), e


def fit(u: np.ndarray, P: np.ndarray, e: np.ndarray, guess: float) -> object:
    return joint_fit(u, P, e, LAW, sigma_force=SIGMA_P, encoder_resolution=Q, contact_guess=guess)


def test_recovers_modulus_and_contact() -> None:
    rng = np.random.default_rng(1)
    u, P, e = curve(400e3, 10.0e-3, rng)
    r = joint_fit(u, P, e, LAW, sigma_force=SIGMA_P, encoder_resolution=Q, contact_guess=10.2e-3)
    assert r.success, r.message
    assert r.modulus == pytest.approx(400e3, rel=0.02)
    assert r.contact == pytest.approx(10.0e-3, abs=5e-6)
    assert r.ci_low is not None
    assert r.ci_high is not None
    assert r.ci_low < 400e3 < r.ci_high
    assert r.contact_low is not None
    assert r.contact_high is not None
    assert r.contact_low <= 10.0e-3 <= r.contact_high
    assert r.rms == pytest.approx(1.0, abs=0.15)
    assert r.n_contact > 100


def test_the_contact_guess_only_starts_the_search() -> None:
    rng = np.random.default_rng(2)
    u, P, e = curve(700e3, 5e-3, rng)
    a = joint_fit(u, P, e, LAW, sigma_force=SIGMA_P, contact_guess=5.3e-3)
    b = joint_fit(u, P, e, LAW, sigma_force=SIGMA_P, contact_guess=4.7e-3)
    assert a.success
    assert b.success
    assert a.modulus == pytest.approx(b.modulus, rel=1e-5)
    assert a.contact == pytest.approx(b.contact, abs=1e-8)


def test_outliers_do_not_pull_the_robust_fit() -> None:
    rng = np.random.default_rng(3)
    u, P, e = curve(300e3, 0.0, rng)
    P[::25] += 1.0  # 4 % of the samples 30 sigma off
    r = joint_fit(u, P, e, LAW, sigma_force=SIGMA_P, contact_guess=0.0)
    assert r.success
    assert r.modulus == pytest.approx(300e3, rel=0.03)


@pytest.mark.slow
def test_interval_coverage_is_about_95_percent() -> None:
    rng = np.random.default_rng(20240611)
    trials, hits = 200, 0
    for _ in range(trials):
        E = float(rng.uniform(250e3, 1100e3))
        x0 = float(rng.uniform(-1e-3, 1e-3))
        u, P, e = curve(E, x0, rng, n=150)
        P += rng.normal(0.0, 0.5 * SIGMA_P)  # each trial's zero error, common to its samples
        r = joint_fit(
            u,
            P,
            e,
            LAW,
            sigma_force=SIGMA_P,
            encoder_resolution=Q,
            contact_guess=x0 + float(rng.normal(0, 0.2e-3)),
        )
        assert r.success, r.message
        assert r.ci_low is not None
        assert r.ci_high is not None
        hits += r.ci_low <= E <= r.ci_high
    # binomial(200, 0.95): sd 1.5 %; 3 sd band
    assert 0.90 <= hits / trials <= 0.995


def test_a_zero_error_on_the_load_is_fitted_not_absorbed_by_the_modulus() -> None:
    rng = np.random.default_rng(7)
    u, P, e = curve(400e3, 0.0, rng)
    offset = 2.0 * SIGMA_P  # a constant load error on every sample (the strains' zero)
    with_p0 = joint_fit(u, P + offset, e, LAW, sigma_force=SIGMA_P, contact_guess=0.0)
    without = joint_fit(
        u, P + offset, e, LAW, sigma_force=SIGMA_P, contact_guess=0.0, load_offset=False
    )
    clean = joint_fit(u, P, e, LAW, sigma_force=SIGMA_P, contact_guess=0.0)
    assert with_p0.success
    assert without.success
    assert clean.success
    assert with_p0.load_offset == pytest.approx(offset, abs=0.3 * SIGMA_P)
    assert with_p0.modulus == pytest.approx(clean.modulus, rel=2e-3)
    assert without.load_offset == 0.0
    # held at zero, the offset moves E by several times the fitted model's own shift
    assert without.modulus is not None
    assert clean.modulus is not None
    assert with_p0.modulus is not None
    assert abs(without.modulus / clean.modulus - 1) > 5 * abs(with_p0.modulus / clean.modulus - 1)


def test_interval_holds_the_modulus_whichever_layer_ratio_the_sample_follows() -> None:
    # the sample follows chi = a/h, the estimate uses the published sqrt(R delta)/h; with little
    # noise the gap between the two is larger than the noise interval
    sphere = ContactLaw(
        3.5e-3, 0.45, 5e-3, bonded=True, layer_ratio_from="sphere", layer_law="dimitriadis"
    )
    rng = np.random.default_rng(8)
    u, P, e = curve(400e3, 0.0, rng, law=sphere)
    P = sphere.force(400e3, np.clip(u - e, 0.0, None)) + rng.normal(0.0, 1e-4, u.size)
    law = dataclasses.replace(sphere, layer_ratio_from="published")
    r = joint_fit(u, P, e, law, sigma_force=1e-4, contact_guess=0.0)
    own = joint_fit(u, P, e, sphere, sigma_force=1e-4, contact_guess=0.0)
    assert r.success
    assert own.success
    assert r.modulus is not None
    assert r.ci_low is not None
    assert r.ci_high is not None
    assert r.model_spread is not None
    assert abs(r.modulus / 400e3 - 1) > 0.01  # the published form alone misses it
    assert r.ci_low <= 400e3 <= r.ci_high
    assert r.model_spread == pytest.approx(abs(float(own.modulus or 0.0) - r.modulus), rel=0.02)


def test_model_form_spread_widens_the_interval_on_thin_layers_only() -> None:
    # the Dimitriadis series' two layer ratios; the exact law has one form and no spread
    rng = np.random.default_rng(4)
    series = dataclasses.replace(LAW, layer_law="dimitriadis")
    u, P, e = curve(400e3, 0.0, rng, law=series)
    thin = joint_fit(u, P, e, series, sigma_force=SIGMA_P, contact_guess=0.0)
    exact = joint_fit(u, P, e, LAW, sigma_force=SIGMA_P, contact_guess=0.0)
    assert exact.model_spread == 0.0
    half = ContactLaw(3.5e-3, 0.45, None)
    u2, P2, e2 = curve(400e3, 0.0, rng, law=half)
    thick = joint_fit(u2, P2, e2, half, sigma_force=SIGMA_P, contact_guess=0.0)
    assert thin.model_spread is not None
    assert thin.model_spread > 0
    assert thick.model_spread == 0.0


def test_too_few_points_is_an_explicit_failure() -> None:
    rng = np.random.default_rng(5)
    u, P, e = curve(400e3, 0.0, rng, n=300)
    r = joint_fit(u[:10], P[:10], e[:10], LAW, sigma_force=SIGMA_P)
    assert not r.success
    assert r.modulus is None
    assert "too few points" in r.message


def test_no_contact_is_an_explicit_failure() -> None:
    rng = np.random.default_rng(6)
    u = np.linspace(0.0, 1e-3, 200)
    P = rng.normal(0.0, SIGMA_P, u.size)
    r = joint_fit(u, P, 0.0, LAW, sigma_force=SIGMA_P, contact_guess=0.5e-3)
    assert not r.success
    assert r.modulus is None
    assert "no contact" in r.message


def test_each_steps_failure_names_the_step() -> None:
    # the steps raise FitFailed; the recipe returns it as a result with the step's message
    rng = np.random.default_rng(11)
    u, P, e = curve(400e3, 0.0, rng)
    late_guess = joint_fit(u, P, e, LAW, sigma_force=SIGMA_P, contact_guess=5e-3)
    assert late_guess.success  # a guess only seeds the scan, which covers the whole record
    ends_early = joint_fit(u[:100], P[:100], e[:100], LAW, sigma_force=SIGMA_P)
    assert not ends_early.success  # the record stops before the contact
    assert ends_early.message.startswith("no contact")
    out_of_budget = joint_fit(u, P, e, LAW, sigma_force=SIGMA_P, contact_guess=0.0, max_nfev=2)
    assert not out_of_budget.success
    assert out_of_budget.message.startswith("least squares did not converge")
    assert out_of_budget.nfev > 0
    strict = joint_fit(
        u, P, e, LAW, sigma_force=SIGMA_P, contact_guess=0.0, min_contact_points=10**4
    )
    assert not strict.success
    assert "samples past the fitted contact point" in strict.message
    assert strict.n_contact > 100  # the count the refinement reached
    assert strict.law == LAW.name
    assert strict.n_points == u.size


def test_a_non_finite_contact_guess_raises_rather_than_fails() -> None:
    rng = np.random.default_rng(12)
    u, P, e = curve(400e3, 0.0, rng)
    with pytest.raises(ValueError, match="contact_guess"):
        joint_fit(u, P, e, LAW, sigma_force=SIGMA_P, contact_guess=float("nan"))


def test_bad_input_raises() -> None:
    u = np.linspace(0, 1e-3, 50)
    with pytest.raises(ValueError, match="force"):
        joint_fit(u, np.zeros(49), 0.0, LAW, sigma_force=SIGMA_P)
    with pytest.raises(ValueError, match="sigma_force"):
        joint_fit(u, np.zeros(50), 0.0, LAW, sigma_force=0.0)
    with pytest.raises(ValueError, match="confidence"):
        joint_fit(u, np.zeros(50), 0.0, LAW, sigma_force=SIGMA_P, confidence=1.0)


def test_grid_fits_in_blocks_match_the_whole_matrix_closed_form() -> None:
    # the blocked, depth-sorted evaluation against the plain (K, N) one it replaced
    rng = np.random.default_rng(9)
    u, P, e = curve(400e3, 0.0, rng, n=600)  # 600 samples: 27 rows a block, 5 blocks
    depth_base = u - e
    w = np.full(u.size, SIGMA_P**-2)
    grid = np.linspace(-0.5e-3, 0.4e-3, 121)
    laws = [LAW, dataclasses.replace(LAW, layer_ratio_from="sphere")]
    for offset in (True, False):
        fits = grid_fits(laws, depth_base, P, w, grid, offset)
        for law, fit in zip(laws, fits, strict=True):
            depth = depth_base[None, :] - grid[:, None]
            f = np.where(depth > 0, law.shape(np.maximum(depth, 0.0))[0], 0.0)
            for got, want in zip(fit, closed_form(f, P, w, offset), strict=True):
                np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12 * np.max(np.abs(want)))


def test_profiles_in_lockstep_are_each_forms_own_profile() -> None:
    # a start span far inside the interval makes the grids widen; profiled together, each form
    # must get what it gets alone
    rng = np.random.default_rng(10)
    u, P, e = curve(400e3, 0.0, rng)
    w = np.full(u.size, SIGMA_P**-2)
    laws = [LAW, dataclasses.replace(LAW, layer_ratio_from="sphere")]
    span = 2e-7
    args = (u - e, P, w, 0.0, span, 3.84, -1e-3, 1e-3, True)
    together = profiles(laws, *args)
    alone = [profiles([law], *args)[0] for law in laws]
    assert [dataclasses.replace(p, best=0) for p in together if p is not None] == alone
    for prof in together:
        assert prof is not None
        assert prof.contact_high - prof.contact_low > 2 * span  # it did widen


def test_covers_reads_the_interval() -> None:
    fit = JointFit(True, "ok", modulus=1.0e5, ci_low=0.9e5, ci_high=1.1e5)
    assert fit.covers(1.0e5)
    assert fit.covers(0.9e5)
    assert not fit.covers(1.2e5)
    assert not JointFit(False, "no contact").covers(1.0e5)
