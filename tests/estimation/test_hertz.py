"""Hertz sphere (paper Eq. 13) and flat punch: known values, round trips, validity, failures."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from palpate.estimation.contact.hertz import (
    contact_radius,
    hertz_force,
    hertz_modulus,
    hertz_validity,
    punch_force,
    punch_modulus,
)

moduli = st.floats(1e2, 1e9)
depths = st.floats(1e-7, 1e-2)
radii = st.floats(1e-4, 1e-1)
poisson = st.floats(0.0, 0.5)


def test_paper_equation_13() -> None:
    # E = 3/4 P (1 - nu^2) / sqrt(delta^3 R): 1 N at 1 mm into nu = 0.5 with R = 3.5 mm.
    E = hertz_modulus(1.0, 1e-3, 3.5e-3, 0.5)
    assert float(E) == pytest.approx(0.75 * 0.75 / math.sqrt(1e-9 * 3.5e-3), rel=1e-15)


def test_punch_known_value() -> None:
    assert float(punch_force(1e5, 1e-3, 2e-3, 0.0)) == pytest.approx(2 * 2e-3 * 1e5 * 1e-3)


@given(E=moduli, delta=depths, R=radii, nu=poisson)
def test_hertz_round_trip(E: float, delta: float, R: float, nu: float) -> None:
    P = hertz_force(E, delta, R, nu)
    assert float(hertz_modulus(P, delta, R, nu)) == pytest.approx(E, rel=1e-12)


@given(E=moduli, delta=depths, a=radii, nu=poisson)
def test_punch_round_trip(E: float, delta: float, a: float, nu: float) -> None:
    P = punch_force(E, delta, a, nu)
    assert float(punch_modulus(P, delta, a, nu)) == pytest.approx(E, rel=1e-12)


def test_vectorised() -> None:
    delta = np.linspace(1e-4, 1e-3, 5)
    P = hertz_force(np.array([[1e4], [2e4]]), delta, 3.5e-3, 0.45)
    assert P.shape == (2, 5)
    np.testing.assert_allclose(P[1], 2 * P[0], rtol=1e-15)
    np.testing.assert_allclose(hertz_modulus(P, delta, 3.5e-3, 0.45)[0], 1e4, rtol=1e-12)
    assert float(contact_radius(1e-3, 4e-3)) == pytest.approx(2e-3)


def test_validity_flags_and_warnings() -> None:
    ok = hertz_validity(1e-4, 3.5e-3, thickness=0.05)
    assert bool(ok.ok)
    assert ok.warnings == ()
    deep = hertz_validity(np.array([1e-4, 1e-3]), 3.5e-3)
    assert deep.small_strain.tolist() == [True, False]
    assert "small-strain" in deep.warnings[0]
    assert np.isnan(deep.contact_ratio).all()
    thin = hertz_validity(3e-4, 3.5e-3, thickness=5e-3)
    assert float(thin.contact_ratio) == pytest.approx(math.sqrt(3e-4 * 3.5e-3) / 5e-3)
    assert not bool(thin.thick_sample)
    assert not bool(thin.ok)
    assert "too thin" in thin.warnings[0]


@pytest.mark.parametrize(
    ("fn", "args", "name"),
    [
        (hertz_force, (-1.0, 1e-3, 1e-3, 0.3), "E"),
        (hertz_force, (1.0, math.nan, 1e-3, 0.3), "delta"),
        (hertz_force, (1.0, 1e-3, 0.0, 0.3), "R_tip"),
        (hertz_force, (1.0, 1e-3, 1e-3, 0.6), "nu"),
        (hertz_modulus, (-1.0, 1e-3, 1e-3, 0.3), "P"),
        (hertz_modulus, (1.0, 0.0, 1e-3, 0.3), "delta"),
        (punch_force, (1.0, 1e-3, -1e-3, 0.3), "radius"),
        (punch_modulus, (1.0, 1e-3, 1e-3, math.nan), "nu"),
        (hertz_validity, (1e-3, 1e-3, -1.0), "thickness"),
    ],
)
def test_bad_input_names_the_argument(fn, args, name) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ValueError, match=rf"^{name} "):
        fn(*args)
