"""Quasi-linear viscoelastic tissue against closed forms of a ramp-and-hold."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import dawsn

from sim.viscoelastic import StandardLinearSolid, ViscoelasticState, force_history, step

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
    state = ViscoelasticState(elastic_force=law.force_and_stiffness_at(1e-3)[0], memory=3.0)
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
