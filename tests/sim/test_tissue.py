"""The simulated tissue law: Hertz baseline, Dimitriadis thin layer, Sneddon sphere, inverse."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from palpate.sim.tissue import CHI_MAX, TissueModel

R_TIP = 3.5e-3


def hertz(E: float, nu: float, delta: np.ndarray) -> np.ndarray:
    return 4.0 / 3.0 * E / (1.0 - nu**2) * math.sqrt(R_TIP) * delta**1.5


VARIANTS = [
    {},
    {"large_indentation": True},
    {"thickness": 5e-3},
    {"thickness": 2e-3, "bonded": False},
    {"thickness": 1e-3, "poisson": 0.0},
    {"thickness": 3e-3, "large_indentation": True},
    {"thickness": 1e-4, "bonded": False, "large_indentation": True, "poisson": 0.3},
]

models = st.builds(
    lambda E, nu, kw: TissueModel(modulus=E, **{"poisson": nu, **kw}),
    E=st.floats(1e3, 5e7),
    nu=st.floats(0.0, 0.5),
    kw=st.sampled_from(VARIANTS),
)


def test_half_space_is_hertz() -> None:
    d = np.linspace(0.0, 2e-3, 101)
    t = TissueModel(modulus=5e5, poisson=0.45)
    np.testing.assert_allclose(t.force(d), hertz(5e5, 0.45, d), rtol=1e-15)
    np.testing.assert_allclose(t.stiffness(d), 2 * 5e5 / (1 - 0.45**2) * np.sqrt(R_TIP * d))


@pytest.mark.parametrize("bonded", [True, False])
def test_thickness_to_infinity_recovers_hertz(bonded: bool) -> None:
    d = np.linspace(0.0, 1e-3, 51)
    base = TissueModel(modulus=5e5).force(d)
    for h, rtol in [(1.0, 1e-1), (1e3, 1e-4), (1e6, 1e-7)]:
        thick = TissueModel(modulus=5e5, thickness=h, bonded=bonded).force(d)
        np.testing.assert_allclose(thick, base, rtol=rtol)
    off = TissueModel(modulus=5e5, thickness=1e-3, finite_thickness=False).force(d)
    np.testing.assert_array_equal(off, base)


def test_dimitriadis_incompressible_coefficients() -> None:
    # Dimitriadis et al. 2002, Eq. 12 with nu = 0.5: 1.133, 1.283, 0.769 (and |0.0975|).
    k = TissueModel(modulus=1e5, poisson=0.5, bonded=True).layer_coefficients()
    np.testing.assert_allclose(k[:3], [1.133, 1.283, 0.769], atol=1e-3)
    assert abs(k[3]) == pytest.approx(0.0975, abs=1e-4)
    # sliding: the frictionless base's first-order term, the same at every nu (not 0.884)
    for nu in (0.0, 0.5):
        kn = TissueModel(modulus=1e5, poisson=nu, bonded=False).layer_coefficients()
        np.testing.assert_allclose(kn[0], -2 * -1.1675768 / math.pi)


def test_thin_layer_is_stiffer_and_bonded_stiffest() -> None:
    d = np.linspace(1e-5, 1e-3, 50)
    half = TissueModel(modulus=5e5).force(d)
    loose = TissueModel(modulus=5e5, thickness=3e-3, bonded=False).force(d)
    bonded = TissueModel(modulus=5e5, thickness=3e-3, bonded=True).force(d)
    assert np.all(loose > half)
    assert np.all(bonded > loose)


def test_sneddon_sphere_limits() -> None:
    E, nu = 4e5, 0.5
    t = TissueModel(modulus=E, poisson=nu, large_indentation=True)
    d = np.array([1e-9, 1e-7, 1e-5]) * R_TIP
    np.testing.assert_allclose(t.force(d), hertz(E, nu, d), rtol=2e-6)
    # Softer than the paraboloid at depth, by about delta / (10 R) to first order.
    d = np.array([0.01, 0.05]) * R_TIP
    ratio = t.force(d) / hertz(E, nu, d)
    np.testing.assert_allclose(ratio, 1 - 0.1 * d / R_TIP, rtol=2e-3)
    # Exact parametric form: a = R tanh y, delta = R y tanh y.
    y = 0.7
    delta = R_TIP * y * math.tanh(y)
    f = E / (1 - nu**2) * R_TIP**2 * ((1 + math.tanh(y) ** 2) * y - math.tanh(y))
    assert float(t.force(delta)) == pytest.approx(f, rel=1e-13)
    assert float(t.contact_radius(delta)) == pytest.approx(R_TIP * math.tanh(y), rel=1e-13)


@pytest.mark.parametrize("kw", VARIANTS)
@pytest.mark.parametrize("E", [1e3, 5e5, 5e7])
def test_force_monotone_and_finite_beyond_series_range(kw: dict[str, object], E: float) -> None:
    t = TissueModel(modulus=E, **kw)  # type: ignore[arg-type]
    d = np.concatenate([[0.0], np.geomspace(1e-12, 5e-2, 4000)])
    f = t.force(d)
    k = t.stiffness(d)
    assert np.all(np.isfinite(f))
    assert np.all(np.isfinite(k))
    assert f[0] == 0.0
    assert k[0] == 0.0
    assert np.all(np.diff(f) > 0)
    assert np.all(k[1:] > 0)
    if math.isfinite(t.thickness):
        assert t.layer_ratio(d).max() > CHI_MAX  # the linear continuation was exercised


@given(model=models, x=st.floats(1e-7, 1e-2))
def test_stiffness_is_the_derivative(model: TissueModel, x: float) -> None:
    h = 1e-6 * x
    fd = (model.force(x + h) - model.force(x - h)) / (2 * h)
    assert float(model.stiffness(x)) == pytest.approx(float(fd), rel=1e-6)


@given(model=models, x=st.floats(1e-9, 2e-2))
def test_inverse_round_trip_from_depth(model: TissueModel, x: float) -> None:
    f = model.force(x)
    assert float(model.inverse(f)) == pytest.approx(x, rel=1e-10)


@given(model=models, f=st.floats(1e-8, 50.0))
def test_inverse_round_trip_from_force(model: TissueModel, f: float) -> None:
    d = model.inverse(f)
    assert float(model.force(d)) == pytest.approx(f, rel=1e-10)


def test_inverse_vectorised_keeps_shape_and_zero() -> None:
    t = TissueModel(modulus=3e3, thickness=4e-3, large_indentation=True)
    f = np.array([[0.0, 1e-6], [0.5, 2.0]])
    d = t.inverse(f)
    assert d.shape == f.shape
    assert d[0, 0] == 0.0
    np.testing.assert_allclose(t.force(d), f, rtol=1e-12)
    assert t.force(1e-3).shape == ()


def test_soft_and_stiff_extremes_at_buckling_load() -> None:
    p_cr = 1.2
    soft = TissueModel(modulus=2e3, large_indentation=True)
    stiff = TissueModel(modulus=5e7)
    d_soft = float(soft.inverse(p_cr))
    d_stiff = float(stiff.inverse(p_cr))
    assert d_soft > R_TIP  # kPa tissue swallows the tip: Sneddon still answers, monotone
    assert 1e-6 < d_stiff < 1e-4
    assert float(soft.force(d_soft)) == pytest.approx(p_cr, rel=1e-12)


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"modulus": -1.0}, "modulus"),
        ({"modulus": math.nan}, "modulus"),
        ({"modulus": 1e5, "poisson": 0.6}, "poisson"),
        ({"modulus": 1e5, "thickness": 0.0}, "thickness"),
        ({"modulus": 1e5, "tip_radius": 0.0}, "tip_radius"),
    ],
)
def test_bad_parameters_raise(kw: dict[str, float], match: str) -> None:
    with pytest.raises(ValueError, match=match):
        TissueModel(**kw)  # type: ignore[arg-type]


def test_bad_inputs_raise() -> None:
    t = TissueModel(modulus=1e5)
    with pytest.raises(ValueError, match="delta"):
        t.force(-1e-6)
    with pytest.raises(ValueError, match="delta"):
        t.stiffness(math.nan)
    with pytest.raises(ValueError, match="force"):
        t.inverse([-1.0])


@given(model=models, x=st.floats(1e-10, 2e-2))
def test_scalar_kernels_match_the_array_ones(model: TissueModel, x: float) -> None:
    f, k = model.force_and_stiffness_at(x)
    assert f == pytest.approx(float(model.force(x)), rel=1e-12)
    assert k == pytest.approx(float(model.stiffness(x)), rel=1e-12)
    assert model.inverse_at(f) == pytest.approx(float(model.inverse(f)), rel=1e-11)
    assert model.inverse_at(f) == pytest.approx(x, rel=1e-10)
    assert model.force_and_stiffness_at(0.0) == (0.0, 0.0)
    assert model.inverse_at(0.0) == 0.0
