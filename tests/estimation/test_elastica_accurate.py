"""The accurate (closed-form) solver against independent solutions and exact properties."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad, solve_bvp, solve_ivp

from palpate.estimation.beam.elastica import (
    E_OVER_L_MAX,
    E_OVER_L_PEAK,
    E_OVER_L_TIP_NORMAL,
    P_CRIT,
    P_PEAK,
    post_buckling,
)
from palpate.estimation.beam.elastica.constants import X1


def _rhs(p: float, r: float):  # type: ignore[no-untyped-def]
    def f(_s: float, y: np.ndarray) -> list[float]:
        th, k = y[0], y[1]
        return [k, -p * math.sin(th) - r * math.cos(th), math.sin(th), 2.0 * math.sin(th / 2) ** 2]

    return f


@pytest.mark.parametrize("e", [1e-8, 1e-6, 1e-3, 0.1, 0.33, 0.6, E_OVER_L_MAX])
def test_reintegration_of_the_initial_value_problem(e: float) -> None:
    """DOP853 from the clamp with the solver's p, r, curvature(0) reproduces the whole state."""
    sol = post_buckling(e)
    p, r = float(sol.p), float(sol.r)
    y0 = [0.0, float(sol.curvature(0.0)), 0.0, 0.0]
    ivp = solve_ivp(
        _rhs(p, r), (0, 1), y0, method="DOP853", rtol=1e-13, atol=1e-18, dense_output=True
    )
    s = np.linspace(0.0, 1.0, 41)
    th, kap, y, short = ivp.sol(s)
    scale = np.abs(kap).max()
    np.testing.assert_allclose(sol.theta(s), th, rtol=0, atol=1e-11 * np.abs(th).max())
    np.testing.assert_allclose(sol.curvature(s), kap, rtol=0, atol=1e-11 * scale)
    np.testing.assert_allclose(sol.y(s), y, rtol=0, atol=1e-11 * np.abs(y).max())
    assert abs(kap[-1]) < 1e-11 * scale  # zero moment at the pin
    assert abs(y[-1]) < 1e-11 * np.abs(y).max()  # pin on the axis
    assert short[-1] == pytest.approx(e, rel=1e-10)  # the requested end shortening


@pytest.mark.parametrize("e", [0.02, 0.3, 0.7])
def test_against_solve_bvp(e: float) -> None:
    """An independent boundary-value solve, started from the linear buckling mode."""

    def fun(s: np.ndarray, y: np.ndarray, q: np.ndarray) -> np.ndarray:
        p, r = q
        return np.vstack(
            [y[1], -p * np.sin(y[0]) - r * np.cos(y[0]), np.sin(y[0]), 1 - np.cos(y[0])]
        )

    def bc(ya: np.ndarray, yb: np.ndarray, q: np.ndarray) -> np.ndarray:
        return np.array([ya[0], ya[2], ya[3], yb[1], yb[2], yb[3] - e])

    s = np.linspace(0, 1, 101)
    mode = np.cos(X1 * s) - 1 + X1 * np.sin(X1 * s)
    amp = -math.sqrt(2 * e / np.trapezoid(mode**2, s))
    guess = np.vstack([amp * mode, np.gradient(amp * mode, s), np.zeros_like(s), np.zeros_like(s)])
    r_guess = P_CRIT * amp
    res = solve_bvp(fun, bc, s, guess, p=[P_CRIT, r_guess], tol=1e-10, max_nodes=100000)
    assert res.success, res.message
    sol = post_buckling(e)
    assert res.p[0] == pytest.approx(float(sol.p), rel=1e-8)
    assert res.p[1] == pytest.approx(float(sol.r), rel=1e-8)
    grid = np.linspace(0, 1, 21)
    np.testing.assert_allclose(
        res.sol(grid)[1], sol.curvature(grid), atol=1e-8 * np.abs(sol.curvature(grid)).max()
    )


def test_small_deflection_limit() -> None:
    """p -> P_CRIT linearly in e/L; r, tip angle and curvature grow like sqrt(e/L)."""
    onset = post_buckling(0.0)
    assert float(onset.p) == pytest.approx(P_CRIT, rel=1e-15)
    assert float(onset.r) == 0.0
    assert float(onset.tip_angle) == 0.0
    e = np.array([1e-8, 1e-7, 1e-6])
    sol = post_buckling(e)
    slope = (sol.p - P_CRIT) / e
    # The next term is O(e): slopes agree to ~1e-6 relative; differences ~(p - P_CRIT) ~ 1e-7.
    np.testing.assert_allclose(slope, slope[0], rtol=3e-5)
    for field in (sol.r, sol.tip_angle, sol.mean_curvature(0.5, 0.6)):  # next term O(e)
        np.testing.assert_allclose(field / np.sqrt(e), field[0] / np.sqrt(e[0]), rtol=5e-6)
    # Independent slope from solve_bvp-grade states: finite difference of the accurate p at
    # moderate e extrapolated to 0 (Richardson) must match the onset slope.
    e1, e2 = 1e-3, 2e-3
    p1, p2 = float(post_buckling(e1).p), float(post_buckling(e2).p)
    s1, s2 = (p1 - P_CRIT) / e1, (p2 - P_CRIT) / e2
    assert 2 * s1 - s2 == pytest.approx(slope[0], rel=1e-5)
    # Linear mode shape: theta ~ cos(x1 s) - 1 + x1 sin(x1 s) (up to a factor).
    s = np.linspace(0.05, 0.95, 10)
    mode = np.cos(X1 * s) - 1 + X1 * np.sin(X1 * s)
    th = post_buckling(1e-10).theta(s)
    np.testing.assert_allclose(th / th[-1], mode / mode[-1], rtol=1e-4)


@pytest.mark.parametrize("e", [1e-4, 0.05, 0.4, 0.75])
def test_virtual_work(e: float) -> None:
    """dU/de = p: the load is the derivative of the bending energy U = 1/2 int kappa**2 ds."""

    def energy(x: float) -> float:
        sol = post_buckling(x)
        return 0.5 * quad(lambda s: float(sol.curvature(s)) ** 2, 0, 1, epsabs=0, epsrel=1e-13)[0]

    def central(h: float) -> float:
        return (energy(e + h) - energy(e - h)) / (2 * h)

    h = 1e-3 * e
    dU = (4 * central(h) - central(2 * h)) / 3  # Richardson: O(h**4)
    assert dU == pytest.approx(float(post_buckling(e).p), rel=1e-7)


@pytest.mark.parametrize("e", [1e-8, 0.01, 0.5, E_OVER_L_MAX])
def test_geometry_and_grating_means(e: float) -> None:
    sol = post_buckling(e)
    assert float(sol.x(1.0)) == pytest.approx(1 - e, abs=1e-14)
    assert abs(float(sol.y(1.0))) < 1e-14
    assert float(sol.theta(0.0)) == 0.0
    # Inflection points at the pin and at s = (t - 2K)/t, about 0.3 near onset.
    assert abs(float(sol.curvature(1.0))) < 1e-12 * abs(float(sol.curvature(0.0)))
    # Mean over an interval is the quadrature of the curvature; the order of s0, s1 is free.
    s0, s1 = 0.35, 0.62
    q = quad(lambda s: float(sol.curvature(s)), s0, s1, epsabs=0, epsrel=1e-13)[0] / (s1 - s0)
    assert float(sol.mean_curvature(s0, s1)) == pytest.approx(q, rel=1e-11)
    assert float(sol.mean_curvature(s1, s0)) == pytest.approx(q, rel=1e-11)
    # A vanishing interval is the point curvature.
    assert float(sol.mean_curvature(0.5, 0.5)) == pytest.approx(
        float(sol.curvature(0.5)), rel=1e-12
    )
    # Sign convention: tip angle and main-lobe curvature positive, beam bows toward -y, r <= 0.
    assert float(sol.tip_angle) > 0
    assert float(sol.mean_curvature(0.4, 0.9)) > 0
    assert float(sol.y(0.5)) < 0
    assert float(sol.r) < 0


def test_branch_landmarks() -> None:
    assert pytest.approx(0.33029, abs=1e-5) == E_OVER_L_TIP_NORMAL
    assert float(post_buckling(E_OVER_L_TIP_NORMAL).tip_angle) == pytest.approx(math.pi / 2)
    assert pytest.approx(0.45365, abs=1e-5) == E_OVER_L_PEAK
    assert pytest.approx(23.0096, abs=1e-4) == P_PEAK
    around = post_buckling(E_OVER_L_PEAK + np.array([-1e-3, 0.0, 1e-3]))
    assert around.p[1] == pytest.approx(P_PEAK, rel=1e-15)
    assert around.p[0] < P_PEAK
    assert around.p[2] < P_PEAK
    assert pytest.approx(0.812087, abs=1e-6) == E_OVER_L_MAX
    assert abs(float(post_buckling(E_OVER_L_MAX).p)) < 1e-12
    # The load is compressive over the whole supported branch.
    assert np.all(post_buckling(np.linspace(0, E_OVER_L_MAX * (1 - 1e-9), 50)).p > 0)


def test_array_input_keeps_shape_and_dedupes() -> None:
    e = np.array([[1e-3, 0.1], [1e-3, 0.2]])
    sol = post_buckling(e)
    assert sol.p.shape == (2, 2)
    assert sol.p[0, 0] == sol.p[1, 0]
    assert post_buckling(0.1).p.shape == ()
