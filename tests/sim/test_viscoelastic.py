"""Quasi-linear viscoelastic tissue against closed forms of a ramp-and-hold."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import dawsn

from palpate.sim.viscoelastic import (
    PowerLawSolid,
    StandardLinearSolid,
    ViscoelasticState,
    creep,
    force_history,
    step,
)

TAU = 0.8
RATIO = 0.4
SPEED = 1e-3  # m/s
T_RAMP = 2.0


class PowerLaw:
    """F_e = C delta^n (n = 1: a spring; n = 1.5: Hertz)."""

    def __init__(self, C: float, n: float) -> None:
        self.C, self.n = C, n

    def force_and_stiffness_at(self, delta: float) -> tuple[float, float]:
        return self.C * delta**self.n, self.n * self.C * delta ** (self.n - 1) if delta > 0 else 0.0


def ramp_hold(t: np.ndarray) -> np.ndarray:
    return SPEED * np.minimum(t, T_RAMP)


def memory_linear(t: np.ndarray, C: float) -> np.ndarray:
    """h(t) for F_e = C v t on the ramp, then relaxing: C v tau (1 - e^(-t/tau))."""
    tr = np.minimum(t, T_RAMP)
    return C * SPEED * TAU * (1 - np.exp(-tr / TAU)) * np.exp(-(t - tr) / TAU)


def memory_hertz(t: np.ndarray, C: float) -> np.ndarray:
    """h(t) for F_e = C (v t)^1.5: 1.5 C v^1.5 tau^1.5 (sqrt(T) - D(sqrt(T))), T = t/tau, with
    D Dawson's integral; then relaxing."""
    tr = np.minimum(t, T_RAMP)
    x = np.sqrt(tr / TAU)
    return 1.5 * C * SPEED**1.5 * TAU**1.5 * (x - dawsn(x)) * np.exp(-(t - tr) / TAU)


def closed_form(t: np.ndarray, law: PowerLaw, memory: np.ndarray) -> np.ndarray:
    return RATIO * law.C * ramp_hold(t) ** law.n + (1 - RATIO) * memory


def test_linear_ramp_and_hold_is_exact_on_any_grid() -> None:
    law = PowerLaw(2e3, 1.0)
    rng = np.random.default_rng(3)
    t = np.sort(np.concatenate([[0.0, T_RAMP], rng.uniform(0, 3 * T_RAMP, 300)]))
    f = force_history(StandardLinearSolid(TAU, RATIO), law, t, ramp_hold(t))
    np.testing.assert_allclose(
        f, closed_form(t, law, memory_linear(t, law.C)), rtol=1e-11, atol=1e-15
    )


def test_hertz_ramp_and_hold_converges_at_second_order() -> None:
    law = PowerLaw(5e4, 1.5)
    errors = []
    for n in (50, 100, 200):
        t = np.linspace(0.0, 3 * T_RAMP, 3 * n + 1)
        f = force_history(StandardLinearSolid(TAU, RATIO), law, t, ramp_hold(t))
        exact = closed_form(t, law, memory_hertz(t, law.C))
        errors.append(np.max(np.abs(f - exact)) / np.max(exact))
    assert errors[-1] < 1e-4
    assert errors[0] / errors[1] == pytest.approx(4.0, rel=0.25)
    assert errors[1] / errors[2] == pytest.approx(4.0, rel=0.25)


def test_speed_matters_between_the_two_moduli() -> None:
    law = PowerLaw(5e4, 1.5)
    sls = StandardLinearSolid(TAU, RATIO)
    depth = 2e-3
    peak = {}
    for duration in (1e-4 * TAU, 1e4 * TAU):
        t = np.linspace(0.0, duration, 2001)
        peak[duration] = force_history(sls, law, t, depth * t / duration)[-1]
    elastic = law.force_and_stiffness_at(depth)[0]
    assert peak[1e-4 * TAU] == pytest.approx(elastic, rel=1e-3)  # E_0
    assert peak[1e4 * TAU] == pytest.approx(RATIO * elastic, rel=1e-3)  # E_inf


def test_step_stiffness_is_the_derivative_of_the_step_force() -> None:
    law = PowerLaw(5e4, 1.5)
    sls = StandardLinearSolid(TAU, RATIO)
    state = ViscoelasticState(elastic_force=law.force_and_stiffness_at(1e-3)[0], memory=(3.0,))
    _, k, _ = step(sls, law, state, 1.2e-3, 0.05)
    h = 1e-9
    fp, _, _ = step(sls, law, state, 1.2e-3 + h, 0.05)
    fm, _, _ = step(sls, law, state, 1.2e-3 - h, 0.05)
    assert k == pytest.approx((fp - fm) / (2 * h), rel=1e-6)


def test_bad_parameters_are_rejected() -> None:
    with pytest.raises(ValueError, match="tau"):
        StandardLinearSolid(0.0, 0.5)
    with pytest.raises(ValueError, match="ratio"):
        StandardLinearSolid(1.0, 1.5)
    with pytest.raises(ValueError, match="time step"):
        StandardLinearSolid(1.0, 0.5).weights(-1.0)
    assert StandardLinearSolid(1.0, 0.5).weights(0.0) == (1.0, 1.0)
    assert math.isclose(float(StandardLinearSolid(1.0, 0.5).relaxation(0.0)), 1.0)


# -- the power law, and creep under a held load against each form's closed form ------------------


@pytest.mark.parametrize(("tau", "beta"), [(0.1, 0.5), (0.2, 1.0), (1e-3, 0.2), (1.0, 2.0)])
def test_the_power_laws_prony_series_is_its_relaxation(tau: float, beta: float) -> None:
    solid = PowerLawSolid(tau, 0.3, beta)
    t = np.geomspace(1e-3, 1e4, 400)
    np.testing.assert_allclose(solid.prony.relaxation(t), solid.relaxation(t), rtol=3e-3)
    assert float(solid.prony.relaxation(0.0)) == pytest.approx(1.0, abs=1e-9)
    assert sum(solid.prony.weights) == pytest.approx(0.7, rel=1e-12)


@pytest.mark.parametrize("solid", [StandardLinearSolid(0.4, 0.5), PowerLawSolid(0.1, 0.5, 0.7)])
def test_a_depth_step_relaxes_as_the_relaxation_function(
    solid: StandardLinearSolid | PowerLawSolid,
) -> None:
    law = PowerLaw(2e3, 1.0)
    t = np.concatenate([[0.0, 1e-7], np.geomspace(1e-3, 100.0, 300)])
    depth = np.where(t > 0, 1e-3, 0.0)
    f = force_history(solid, law, t, depth)
    np.testing.assert_allclose(f[2:] / 2.0, solid.relaxation(t[2:] - 1e-7), rtol=3e-3)


def test_creep_of_the_standard_linear_solid_is_its_closed_form() -> None:
    sls = StandardLinearSolid(0.5, 0.4)
    t = np.concatenate([[0.0], np.geomspace(1e-4, 1e3, 2000)])
    exact = 1 / 0.4 - (1 / 0.4 - 1) * np.exp(-0.4 * t / 0.5)  # retardation time tau / r
    np.testing.assert_allclose(creep(sls, t), exact, rtol=1e-5)


@pytest.mark.parametrize("beta", [0.2, 0.5])
def test_creep_of_the_power_law_is_its_closed_form(beta: float) -> None:
    """G = t^-beta (tau -> 0, r -> 0) creeps as J = t^beta sin(pi beta) / (pi beta) (the
    Laplace pair of the power law); with tau = 1 ms the shift is gone by t/tau = 1e5."""
    solid = PowerLawSolid(1e-3, 1e-9, beta)
    t = np.concatenate([[0.0], np.geomspace(1e-4, 1e3, 3000)])
    late = t >= 100.0
    exact = (t[late] / 1e-3) ** beta * math.sin(math.pi * beta) / (math.pi * beta)
    np.testing.assert_allclose(creep(solid, t)[late], exact, rtol=1e-2)


def test_creep_solves_the_volterra_equation_of_the_exact_kernel() -> None:
    """integral G(t - s) dJ(s) = 1 by direct quadrature with the closed-form G, not the Prony
    series the world steps with: two routes to the same creep."""
    solid = PowerLawSolid(0.05, 0.4, 0.6)
    t = np.linspace(0.0, 5.0, 2001)
    j = creep(solid, t)
    dj = np.diff(j)
    mid = 0.5 * (t[1:] + t[:-1])
    for k in (200, 1000, 2000):
        total = j[0] * float(solid.relaxation(t[k])) + float(
            np.sum(solid.relaxation(t[k] - mid[:k]) * dj[:k])
        )
        assert total == pytest.approx(1.0, abs=3e-3)


def test_bad_power_laws_are_rejected() -> None:
    with pytest.raises(ValueError, match="exponent"):
        PowerLawSolid(0.1, 0.5, 0.0)
    with pytest.raises(ValueError, match="ratio"):
        PowerLawSolid(0.1, 0.0, 0.5)
