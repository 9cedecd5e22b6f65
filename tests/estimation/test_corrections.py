"""Thin-layer and large-indentation corrections against their published limits."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from palpate.estimation.contact.hertz import hertz_force
from palpate.estimation.contact.law import (
    ContactLaw,
    shape_values,
    validity_warnings,
)
from palpate.estimation.contact.layer import (
    BONDED_B0_PER_MOMENT,
    SLIDING_A0,
    SLIDING_B0,
    dimitriadis_bracket,
    dimitriadis_coefficients,
    layer_coefficients,
    layer_kernel,
)
from palpate.estimation.contact.sneddon import sneddon_y, sneddon_y_at
from palpate.sim.tissue import TissueModel

R = 3.5e-3
DEPTHS = np.array([1e-6, 1e-5, 1e-4, 3e-4, 1e-3])


def test_dimitriadis_bonded_incompressible_bracket_is_the_published_one() -> None:
    # Dimitriadis et al. 2002: 1 + 1.133 chi + 1.283 chi^2 + 0.769 chi^3 - 0.0975 chi^4 (nu = 0.5)
    k = dimitriadis_coefficients(0.5, bonded=True)
    assert k == pytest.approx((1.133, 1.283, 0.769, -0.0975), abs=6e-4)


def test_dimitriadis_non_bonded_incompressible_bracket_is_the_published_one() -> None:
    # ... and 1 + 0.884 chi + 0.781 chi^2 + 0.386 chi^3 + 0.0048 chi^4 for a sliding layer
    k = dimitriadis_coefficients(0.5, bonded=False)
    assert k == pytest.approx((0.884, 0.781, 0.386, 0.0048), abs=6e-4)


def kernel_moment(poisson: float, bonded: bool, power: int) -> float:
    """The integral of u^power (K(u) - 1) over u in [0, inf), by quadrature."""
    value, _ = quad(lambda u: u**power * (float(layer_kernel(u, poisson, bonded)) - 1.0), 0, 40)
    return float(value)


@pytest.mark.parametrize("poisson", [0.3, 0.4, 0.45, 0.5])
def test_the_bonded_kernel_gives_dimitriadis_first_order_coefficient(poisson: float) -> None:
    """a0 is the integral of K - 1 (the layer's uniform extra approach): the bonded kernel
    reproduces the published bonded a0, which validates the identity used for the sliding one."""
    published_k1 = dimitriadis_coefficients(poisson, bonded=True)[0]
    assert -2 * kernel_moment(poisson, True, 0) / math.pi == pytest.approx(published_k1, rel=7e-3)


def test_sliding_coefficients_come_from_the_frictionless_kernel_at_every_poisson() -> None:
    a0 = kernel_moment(0.45, False, 0)
    assert kernel_moment(0.1, False, 0) == pytest.approx(a0, rel=1e-12)  # K has no nu
    assert a0 == pytest.approx(SLIDING_A0, abs=1e-6)
    assert BONDED_B0_PER_MOMENT * kernel_moment(0.45, False, 2) == pytest.approx(
        SLIDING_B0, abs=1e-6
    )
    bonded_b0 = (0.6387 - 1.0277 * 0.5 + 1.5164 * 0.25) / 0.5
    assert bonded_b0 / kernel_moment(0.5, True, 2) == pytest.approx(BONDED_B0_PER_MOMENT, abs=1e-6)
    for nu in (0.0, 0.45, 0.5):
        k = layer_coefficients(nu, bonded=False)
        assert k[0] == pytest.approx(-2 * SLIDING_A0 / math.pi, rel=1e-12)
    # the published non-bonded first-order term is right only near nu = 0.27, 13 % high at 0.45
    published = dimitriadis_coefficients(0.45, bonded=False)[0]
    assert published / layer_coefficients(0.45, bonded=False)[0] == pytest.approx(1.135, abs=0.005)
    assert layer_coefficients(0.45, bonded=True) == dimitriadis_coefficients(0.45, bonded=True)


def test_layer_kernel_limits() -> None:
    u = np.array([0.0, 1e-3, 30.0])
    for bonded in (True, False):
        k = layer_kernel(u, 0.45, bonded)
        assert k[0] == 0.0
        assert 0.0 < k[1] < 1e-2
        assert k[2] == pytest.approx(1.0, abs=1e-9)


def test_bracket_is_one_at_zero_thickness_ratio_and_grows() -> None:
    k = dimitriadis_coefficients(0.45, bonded=True)
    b, db = dimitriadis_bracket(np.array([0.0, 0.1, 0.5]), k)
    assert b[0] == 1.0
    assert np.all(np.diff(b) > 0)
    assert db[0] == pytest.approx(k[0])


def test_thick_layer_recovers_hertz() -> None:
    hertz = hertz_force(1.0, DEPTHS, R, 0.45)
    for h in (1.0, 100.0):  # m: chi = sqrt(R delta)/h -> 0
        law = ContactLaw(R, 0.45, thickness=h, large_indentation=False)
        assert law.shape(DEPTHS)[0] == pytest.approx(hertz, rel=2e-3 / h)
    half_space = ContactLaw(R, 0.45, thickness=None, large_indentation=False)
    np.testing.assert_allclose(half_space.shape(DEPTHS)[0], hertz, rtol=1e-14)


def test_sneddon_tends_to_hertz_for_shallow_indentation_and_is_softer_deeper() -> None:
    sneddon = ContactLaw(R, 0.3, thickness=None, large_indentation=True)
    ratio = sneddon.shape(DEPTHS)[0] / hertz_force(1.0, DEPTHS, R, 0.3)
    assert ratio[0] == pytest.approx(1.0 - 0.1 * DEPTHS[0] / R, abs=2e-6)  # delta/R = 3e-4
    # about -0.1 delta/R: 1 % softer at delta/R = 0.1, 2.7 % at 0.29
    assert 0.98 < float(sneddon.shape(0.1 * R)[0] / hertz_force(1.0, 0.1 * R, R, 0.3)) < 0.995
    assert np.all(np.diff(ratio) < 0)


@pytest.mark.parametrize("ratio_from", ["published", "sphere"])
@pytest.mark.parametrize("large", [True, False])
def test_shape_derivative_matches_finite_differences(ratio_from: str, large: bool) -> None:
    law = ContactLaw(R, 0.45, 10e-3, True, large, ratio_from)  # type: ignore[arg-type]
    d = np.array([2e-5, 3e-4, 1.2e-3])
    h = 1e-9
    fd = (law.shape(d + h)[0] - law.shape(d - h)[0]) / (2 * h)
    np.testing.assert_allclose(law.shape(d)[1], fd, rtol=1e-5)


def test_sneddon_y_is_the_root_to_rounding_over_the_whole_range() -> None:
    # the fixed three Newton steps against the guarded scalar iteration (itself within 1 ulp of
    # the root): at most 1 ulp each way, so 2 ulp apart; and y tanh y = d to rounding
    rng = np.random.default_rng(11)
    d = np.concatenate([np.geomspace(1e-12, 1e3, 4001), 10 ** rng.uniform(-12, 3, 4000)])
    y = sneddon_y(d)
    twin = np.array([sneddon_y_at(float(x)) for x in d])
    assert np.max(np.abs(y - twin) / np.spacing(twin)) <= 2.0
    assert np.max(np.abs(y * np.tanh(y) - d) / d) <= 3 * np.finfo(np.float64).eps
    # the limits: y ~ sqrt(d) (1 + d/6) near 0, y = d once tanh(y) rounds to 1
    np.testing.assert_allclose(sneddon_y(np.array([1e-12])), 1e-6 * (1 + 1e-12 / 6), rtol=1e-15)
    assert sneddon_y(np.array([50.0, 1e200]))[1] == 1e200


def test_sneddon_y_at_and_below_zero_is_zero_without_warnings() -> None:
    y = sneddon_y(np.array([0.0, -1.0, 5e-324]))  # numpy warnings are errors in the test run
    assert y[0] == 0.0
    assert y[1] == 0.0
    assert y[2] == pytest.approx(np.sqrt(5e-324), rel=1e-15)


@pytest.mark.parametrize("large", [True, False])
def test_shape_values_are_the_shape_bit_for_bit_for_every_form(large: bool) -> None:
    d = np.concatenate([np.linspace(-1e-3, 2e-3, 301), [0.0]])
    laws = [
        ContactLaw(R, 0.45, h, bonded, large, ratio)
        for h in (None, 5e-3)
        for bonded in (True, False)
        for ratio in ("published", "sphere")
    ]
    for law, values in zip(laws, shape_values(laws, d), strict=True):
        np.testing.assert_array_equal(values, law.shape(d)[0])
    block = d[:300].reshape(3, 100)  # any shape
    np.testing.assert_array_equal(shape_values(laws[:1], block)[0], laws[0].shape(block)[0])


def test_shape_values_refuses_laws_that_share_no_half_space() -> None:
    with pytest.raises(ValueError, match="at least one law"):
        shape_values([], DEPTHS)
    with pytest.raises(ValueError, match="share"):
        shape_values([ContactLaw(R, 0.45), ContactLaw(R, 0.3)], DEPTHS)
    with pytest.raises(ValueError, match="share"):
        shape_values([ContactLaw(R, 0.45), ContactLaw(R, 0.45, large_indentation=False)], DEPTHS)


def test_no_force_before_contact_and_inverse_for_modulus() -> None:
    law = ContactLaw(R, 0.45, 10e-3)
    f, df = law.shape(np.array([-1e-3, 0.0]))
    assert np.all(f == 0.0)
    assert np.all(df == 0.0)
    F = law.force(250e3, DEPTHS)
    np.testing.assert_allclose(law.modulus(F, DEPTHS), 250e3, rtol=1e-12)
    with pytest.raises(ValueError, match="delta"):
        law.modulus(1.0, 0.0)


def test_the_simulator_uses_the_same_constants() -> None:
    for bonded in (True, False):
        tissue = TissueModel(1e5, 0.45, 10e-3, bonded, R, True, True)
        assert tissue.layer_coefficients() == layer_coefficients(0.45, bonded)
    # the sim's composition (chi = a/h with Sneddon's a) is the estimator's alternative one
    tissue = TissueModel(1.0, 0.45, 10e-3, True, R, True, True)
    law = ContactLaw(R, 0.45, 10e-3, True, True, "sphere", layer_law="dimitriadis")
    np.testing.assert_allclose(law.shape(DEPTHS)[0], tissue.force(DEPTHS), rtol=1e-12)
    published = ContactLaw(R, 0.45, 10e-3)
    assert not np.allclose(published.shape(DEPTHS)[0], tissue.force(DEPTHS), rtol=1e-3)


def test_validity_warnings_of_the_series() -> None:
    law = ContactLaw(R, 0.45, 10e-3, layer_law="dimitriadis")
    assert validity_warnings(law, 1e-5) == ()
    deep = validity_warnings(law, 1e-3, misalignment=math.radians(8))
    assert any("Sneddon" in w for w in deep)
    assert any("Dimitriadis thin-layer correction applied" in w for w in deep)
    assert any("8.0 deg off the surface normal" in w for w in deep)
    thin = validity_warnings(ContactLaw(R, 0.45, 1e-3, layer_law="dimitriadis"), 1e-3)
    assert any("beyond the Dimitriadis series' range" in w for w in thin)


def test_validity_warnings_of_the_exact_law_name_its_trusted_domain() -> None:
    law = ContactLaw(R, 0.45, 10e-3)
    assert validity_warnings(law, 1e-5) == ()
    deep = validity_warnings(law, 1e-3, misalignment=math.radians(8))
    assert len(deep) == 2  # the sphere's depth (corrected) and the misalignment
    assert any("corrected with Sneddon's sphere" in w for w in deep)
    assert any("8.0 deg off the surface normal" in w for w in deep)
    # chi = sqrt(3.5 * 1)/1 = 1.87: inside the exact law's domain, but the layer is compressed
    thin = validity_warnings(ContactLaw(R, 0.45, 1e-3), 1e-3)
    assert not any("layer ratio" in w for w in thin)
    assert any("compressed by delta/h = 1" in w for w in thin)
    very_thin = validity_warnings(ContactLaw(R, 0.45, 0.3e-3), 0.2e-3)  # chi = 2.8
    assert not any("layer ratio" in w for w in very_thin)
    beyond = validity_warnings(ContactLaw(R, 0.45, 0.3e-3), 0.4e-3)  # chi = 3.9
    assert any("beyond the exact layer law's trusted domain" in w for w in beyond)
    past = validity_warnings(ContactLaw(R, 0.45, None), 1.2 * R)
    assert any("beyond the exact law's trusted depth" in w for w in past)
    hertz = validity_warnings(ContactLaw(R, 0.45, None, large_indentation=False), 1e-3)
    assert any("small-strain" in w and "corrected" not in w for w in hertz)


def test_bad_input_is_rejected_by_name() -> None:
    with pytest.raises(ValueError, match="poisson"):
        dimitriadis_coefficients(0.6, True)
    with pytest.raises(ValueError, match="tip_radius"):
        ContactLaw(0.0, 0.45)
    with pytest.raises(ValueError, match="thickness"):
        ContactLaw(R, 0.45, thickness=-1.0)
    with pytest.raises(ValueError, match="layer_ratio_from"):
        ContactLaw(R, 0.45, 1e-2, True, True, "paraboloid")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="delta"):
        ContactLaw(R, 0.45).shape(np.array([np.nan]))
    with pytest.raises(ValueError, match="misalignment"):
        validity_warnings(ContactLaw(R, 0.45), 1e-4, misalignment=math.inf)
