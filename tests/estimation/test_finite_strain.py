"""The neo-Hookean departure (``estimation.contact.finite_strain``): its parts against closed forms,
the shipped rows against a fresh solve, and the whole against the world's finite elements (an
independent method: the FE solves the nonlinear problem, the departure is second-order
elasticity on the exact linear layer's fields)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from benchmarks.finite_strain import fe_departure
from palpate.estimation.contact.finite_strain.departure import _density, cubic_energy, departure_row
from palpate.estimation.contact.finite_strain.fields import Grid, pressure_transform, surface
from palpate.estimation.contact.finite_strain.table import (
    INVERSE_THICKNESS,
    POISSON,
    departure_curve,
    load_rows,
)
from palpate.estimation.contact.law import ContactLaw, shape_values


def _neo_hookean(H: tuple[float, ...], nu: float) -> float:
    """The full Simo-Taylor energy (E* = 1) of the axisymmetric gradient H."""
    hrr, hrz, hzr, hzz, htt = H
    mu, bulk = 0.5 * (1 - nu), (1 - nu * nu) / (3 * (1 - 2 * nu))
    F = np.array([[1 + hrr, 0, hrz], [0, 1 + htt, 0], [hzr, 0, 1 + hzz]])
    J = np.linalg.det(F)
    return 0.5 * mu * (J ** (-2 / 3) * np.sum(F * F) - 3) + 0.5 * bulk * (J - 1) ** 2


@pytest.mark.parametrize("nu", [0.3, 0.45, 0.49])
def test_cubic_energy_is_the_odd_part_of_the_neo_hookean_energy(nu: float) -> None:
    rng = np.random.default_rng(3)
    for _ in range(5):
        H = tuple(rng.normal(size=5))
        t = 1e-3
        odd = (
            _neo_hookean(tuple(t * h for h in H), nu) - _neo_hookean(tuple(-t * h for h in H), nu)
        ) / (2 * t**3)
        cubic = float(cubic_energy(tuple(np.array(h) for h in H), nu))
        assert cubic == pytest.approx(odd, rel=1e-4, abs=1e-6)


def test_half_space_surface_fields_are_hertz() -> None:
    """A small contact on the half-space: the surface pressure and radial displacement of the
    fields are Hertz's (p0 sqrt(1 - r^2); -(1 - 2 nu)(1 + nu)/(3 E) p0 (1 - (1 - r^2)^1.5)/r)."""
    nu, radius = 0.45, 0.02  # a/R
    grid = Grid.default()
    tau, dens, _ = _density(radius, math.inf, nu, True)
    ur, p, _ = surface(grid, pressure_transform(grid.xi, tau, dens), nu, True, math.inf)
    r = grid.r_in
    p0 = 2.0 * radius / math.pi  # 2 E* a / (pi R), in units of a and E* = 1
    inside = r < 0.9
    assert np.allclose(p[inside], p0 * np.sqrt(1 - r[inside] ** 2), rtol=2e-3)
    hertz = -(1 - 2 * nu) * (1 + nu) / (3 * (1 - nu * nu)) * p0 * (1 - (1 - r**2) ** 1.5) / r
    assert np.allclose(ur[inside], hertz[inside], rtol=5e-3)


def test_shipped_rows_are_what_the_solver_gives() -> None:
    rows = load_rows()
    j, i = POISSON.index(0.45), INVERSE_THICKNESS.index(2.0)
    row = departure_row(0.5, 0.45, bonded=True)
    assert np.allclose(row.depth_ratio, rows.depth[j, 0, i], rtol=1e-12)
    assert np.allclose(row.frictionless, rows.frictionless[j, 0, i], atol=1e-9)
    assert np.allclose(row.sticking, rows.sticking[j, 0, i], atol=1e-9)


@pytest.mark.parametrize("thickness", [1.5, 2.0, 3.0])
@pytest.mark.parametrize("base", ["bonded", "sliding"])
def test_frictionless_departure_matches_the_worlds_finite_elements(
    thickness: float, base: str
) -> None:
    """Second-order elasticity against the FE's nonlinear solves, delta/h 0.05-0.3: within
    0.45 % in force (the FE departures reach 6.5 %)."""
    depth, fe = fe_departure(f"layers-nh-{thickness:g}mm-{base}-frictionless")
    strain = depth * 3.5 / thickness
    curve = departure_curve(0.45, base == "bonded", 3.5 / thickness, "frictionless")
    at = np.array([0.05, 0.1, 0.15, 0.2, 0.25, 0.3])
    ours = curve.at(at * thickness / 3.5)[0]
    assert np.max(np.abs(ours - np.interp(at, strain, fe))) < 4.5e-3


def test_neo_hookean_law_is_the_linear_law_times_the_departure() -> None:
    linear = ContactLaw(3.5e-3, 0.45, 1.5e-3, True)
    neo = dataclasses.replace(linear, material="neo-hookean")
    delta = np.linspace(-1e-4, 4e-4, 51)
    f_lin, _ = linear.shape(delta)
    f_neo, df_neo = neo.shape(delta)
    d, _ = neo.finite_strain.at(np.maximum(delta, 0.0) / 3.5e-3)  # type: ignore[union-attr]
    assert np.allclose(f_neo, f_lin * (1 + d), rtol=1e-12, atol=0)
    assert np.all(f_neo[delta > 5e-5] > f_lin[delta > 5e-5])  # a thin bonded layer stiffens
    step = 1e-8
    numeric = (neo.shape(delta + step)[0] - neo.shape(delta - step)[0]) / (2 * step)
    inside = delta > 2 * step
    assert np.allclose(df_neo[inside], numeric[inside], rtol=2e-3)
    assert np.array_equal(shape_values([neo, linear], delta)[0], f_neo)


def test_sticking_tip_stiffens_a_thin_bonded_layer_more() -> None:
    slide = departure_curve(0.45, True, 3.5 / 1.5, "frictionless")
    stick = departure_curve(0.45, True, 3.5 / 1.5, "sticking")
    x = np.array([0.2 * 1.5 / 3.5])  # delta/h = 0.2
    assert stick.at(x)[0][0] > slide.at(x)[0][0] > 0.02


def test_curve_rejects_bad_input() -> None:
    with pytest.raises(ValueError, match="tip"):
        departure_curve(0.45, True, 1.0, "greasy")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="material"):
        ContactLaw(3.5e-3, 0.45, material="rubber")  # type: ignore[arg-type]


def test_deep_the_neo_hookean_law_widens_and_past_its_rows_is_flagged() -> None:
    from palpate.estimation.contact.law import validity_warnings
    from palpate.estimation.jointfit.modelform import FINITE_STRAIN, model_form

    neo = ContactLaw(1.3e-3, 0.45, 10e-3, True, material="neo-hookean", tip="sticking")
    shallow, deep, past = 0.2 * 1.3e-3, 0.5 * 1.3e-3, 0.7 * 1.3e-3
    assert not any("trusted depth" in w for w in validity_warnings(neo, deep))
    assert any("neo-Hookean law's trusted depth" in w for w in validity_warnings(neo, past))
    linear = dataclasses.replace(neo, material="linear")
    assert model_form(neo, shallow).finite_strain >= model_form(linear, shallow).finite_strain
    assert model_form(neo, deep).finite_strain >= FINITE_STRAIN * 0.5


def test_a_sticking_tip_on_a_sliding_layer_carries_its_whole_effect_in_the_bound() -> None:
    """On a sliding base the world's FE leaves the sticking approximation's two limits (under
    the lung's 10 mm tip, h/R 0.16-0.25), so the bound carries the stick's whole departure from
    the frictionless law there; on a bonded base, where the limits hold the FE, half their
    spread."""
    from palpate.estimation.jointfit.modelform import model_form

    radius, thickness = 10e-3, 1.6e-3
    depth = 0.2 * thickness
    x = np.linspace(0.0, depth / radius, 33)
    for bonded in (False, True):
        law = ContactLaw(radius, 0.45, thickness, bonded, material="neo-hookean", tip="sticking")
        whole = np.max(
            np.abs(
                departure_curve(0.45, bonded, radius / thickness, "sticking").at(x)[0]
                - departure_curve(0.45, bonded, radius / thickness, "frictionless").at(x)[0]
            )
        )
        bound = model_form(law, depth).finite_strain
        assert bool(bound >= whole) is (not bonded)
