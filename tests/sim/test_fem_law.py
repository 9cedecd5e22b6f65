"""The tissue law read from a finite-element table: the interface the contact solver calls."""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

from palpate.estimation.contact.hertz import hertz_force
from palpate.sim.fem.generate import SHIPPED
from palpate.sim.fem.law import FeTissueLaw, pchip_slopes
from palpate.sim.fem.table import load_table

R_TIP = 3.5e-3
E = 5e5


@pytest.fixture(scope="module")
def law() -> FeTissueLaw:
    return FeTissueLaw(SHIPPED["paper-linear"], modulus=E, tip_radius=R_TIP)


def test_the_law_passes_through_the_table(law: FeTissueLaw) -> None:
    table = load_table(law.problem)
    f, _ = law.force_and_stiffness(R_TIP * table.depths)
    np.testing.assert_allclose(f, E * R_TIP**2 * table.forces, rtol=1e-12)


def test_small_depth_tends_to_hertz(law: FeTissueLaw) -> None:
    d = np.array([1e-9, 1e-8])
    f, _ = law.force_and_stiffness(d)
    np.testing.assert_allclose(f, hertz_force(E, d, R_TIP, law.problem.poisson), rtol=2e-3)
    assert law.force_and_stiffness_at(0.0) == (0.0, 0.0)


def test_increasing_with_continuous_stiffness(law: FeTissueLaw) -> None:
    d = np.linspace(0.0, 2.0 * law.depth_limit, 4001)  # twice as deep as the table
    f, k = law.force_and_stiffness(d)
    assert np.all(np.diff(f) > 0)
    assert np.all(k[1:] > 0)
    h = 1e-9
    f_plus, _ = law.force_and_stiffness(d[1:] + h)
    f_minus, _ = law.force_and_stiffness(d[1:] - h)
    np.testing.assert_allclose((f_plus - f_minus) / (2 * h), k[1:], rtol=1e-5)
    knots = R_TIP * load_table(law.problem).depths  # C1 across every knot and the table's end
    _, k_below = law.force_and_stiffness(knots * (1 - 1e-12))
    _, k_above = law.force_and_stiffness(knots * (1 + 1e-12))
    np.testing.assert_allclose(k_above, k_below, rtol=1e-9)


def test_scalar_and_array_paths_agree(law: FeTissueLaw) -> None:
    d = np.linspace(0.0, 1.5 * law.depth_limit, 37)
    f, k = law.force_and_stiffness(d)
    pairs = np.array([law.force_and_stiffness_at(float(x)) for x in d])
    np.testing.assert_allclose(pairs[:, 0], f, rtol=1e-13, atol=0)
    np.testing.assert_allclose(pairs[:, 1], k, rtol=1e-13, atol=0)
    back = law.inverse(f)
    np.testing.assert_allclose(back, d, rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose([law.inverse_at(float(x)) for x in f], back, rtol=1e-13, atol=0)


def test_the_law_scales_with_modulus_and_tip_radius(law: FeTissueLaw) -> None:
    other = FeTissueLaw(law.problem, modulus=2 * E, tip_radius=2 * R_TIP)
    d = np.linspace(0.0, law.depth_limit, 11)
    np.testing.assert_allclose(other.force(2 * d), 8 * law.force(d), rtol=1e-12)


def test_hashable_and_equal_by_value(law: FeTissueLaw) -> None:
    twin = FeTissueLaw(SHIPPED["paper-linear"], modulus=E, tip_radius=R_TIP)
    assert twin == law
    assert hash(twin) == hash(law)
    assert twin.key == law.key

    @functools.lru_cache(maxsize=4)
    def cached(x: FeTissueLaw) -> float:
        return float(x.force(1e-3))

    assert cached(law) == cached(twin)
    assert cached.cache_info().hits == 1


def test_bad_input_is_rejected(law: FeTissueLaw) -> None:
    with pytest.raises(ValueError, match="delta"):
        law.force_and_stiffness(-1e-3)
    with pytest.raises(ValueError, match="delta"):
        law.force_and_stiffness_at(math.nan)
    with pytest.raises(ValueError, match="force"):
        law.inverse_at(-1.0)
    with pytest.raises(ValueError, match="modulus"):
        FeTissueLaw(law.problem, modulus=0.0, tip_radius=R_TIP)


def test_neo_hookean_layer_is_stiffer_than_linear_at_depth() -> None:
    lin = FeTissueLaw(SHIPPED["paper-linear"], modulus=E, tip_radius=R_TIP)
    neo = FeTissueLaw(SHIPPED["paper-neo-hookean"], modulus=E, tip_radius=R_TIP)
    assert neo.force_and_stiffness_at(1e-4)[0] == pytest.approx(
        lin.force_and_stiffness_at(1e-4)[0], rel=0.01
    )
    assert neo.force_and_stiffness_at(2.5e-3)[0] != pytest.approx(
        lin.force_and_stiffness_at(2.5e-3)[0], rel=0.005
    )


def test_pchip_slopes_are_scipys() -> None:
    rng = np.random.default_rng(7)
    for _ in range(20):
        x = np.sort(rng.uniform(0, 1, 9))
        y = np.cumsum(rng.normal(0, 1, 9)) * rng.choice([0.0, 1.0], 9, p=[0.2, 0.8])
        np.testing.assert_allclose(
            pchip_slopes(x, y), PchipInterpolator(x, y)(x, 1), rtol=1e-12, atol=1e-12
        )
