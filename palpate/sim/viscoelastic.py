"""Viscoelastic tissue: quasi-linear viscoelasticity (Fung) with a chosen relaxation function.

The force is the elastic law's force history filtered by a reduced relaxation function G::

    F(t) = integral_0^t G(t - s) dF_e(delta(s))/ds ds,

with ``F_e`` the elastic law at the instantaneous modulus E_0 and ``G(0) = 1``, ``G(inf) = r =
E_inf / E_0`` in (0, 1]: a fast indentation meets E_0, a slow one (or a held one, once relaxed)
E_inf. Two forms, selectable per sample (``config.sample``):

- :class:`StandardLinearSolid`: ``G(t) = r + (1 - r) exp(-t / tau)``, one time constant (a
  silicone or gel phantom's usual description);
- :class:`PowerLawSolid`: ``G(t) = r + (1 - r) (1 + t / tau)^-beta``, a relaxation with no
  single time constant (soft tissue's constant-phase behaviour: lung parenchyma relaxes as a
  power law of time, Suki et al. 1994; the ``1 + t/tau`` keeps G finite at t = 0 and ``r`` gives
  it a relaxed modulus). The estimator (``estimation.relaxation``) fits neither form.

Both are stepped as a Prony series ``G = r + sum_k w_k exp(-t / tau_k)`` (:class:`Prony`): the
standard linear solid is one term, exactly; the power law is fitted once per sample by
non-negative least squares on relative error with four terms a decade from 0.1 ms to 10^5 s
(:func:`power_law_prony`; within 0.3 % of G from 1 ms to 10^4 s, ``tests/sim/test_viscoelastic``).
With ``F = r F_e + sum_k w_k h_k``, each memory ``h_k = integral exp(-(t - s)/tau_k) dF_e`` obeys,
over a step dt in which F_e changes linearly in time (the exact exponential recursion of a
piecewise-linear input)::

    h_{n+1} = exp(-dt/tau) h_n + (tau/dt) (1 - exp(-dt/tau)) (F_e,n+1 - F_e,n),

one state per trial (the last F_e and the memories), O(terms) per step, unconditionally stable,
exact for a force that is linear in time and second-order accurate otherwise.

Simplified: the kernel is separable (the same relaxation at every depth, as QLV assumes), and
the returned force is not clipped: when the tip retracts faster than the tissue relaxes it can
turn negative, which a caller reads as loss of contact.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import nnls  # type: ignore[import-untyped,unused-ignore]

FloatArray = NDArray[np.float64]

PRONY_SPAN_S = (1e-4, 1e5)  # the power law's Prony times (s): 0.1 ms to ~1 day
PRONY_PER_DECADE = 4


class ElasticLaw(Protocol):
    """What the viscoelastic model needs from an elastic law (TissueModel, FeTissueLaw)."""

    def force_and_stiffness_at(self, delta: float) -> tuple[float, float]: ...


@dataclass(frozen=True)
class Prony:
    """``G(t) = ratio + sum_k weights[k] exp(-t / taus[k])`` with ``sum(weights) = 1 - ratio``."""

    ratio: float
    taus: tuple[float, ...]
    weights: tuple[float, ...]

    def relaxation(self, t: ArrayLike) -> FloatArray:
        tt = np.asarray(t, dtype=np.float64)[..., None]
        w, tau = np.asarray(self.weights), np.asarray(self.taus)
        return np.asarray(self.ratio + np.sum(w * np.exp(-tt / tau), axis=-1))

    def step_weights(self, dt: float) -> tuple[FloatArray, FloatArray]:
        """(decay, gain) per term of a step dt >= 0 (s): exp(-dt/tau), (tau/dt)(1 - e^(-dt/tau))."""
        if not (dt >= 0 and math.isfinite(dt)):
            raise ValueError(f"time step must be finite and >= 0, got {dt}")
        x = dt / np.asarray(self.taus)
        if dt == 0:
            return np.ones_like(x), np.ones_like(x)
        return np.exp(-x), -np.expm1(-x) / x


def _checked(tau: float, ratio: float) -> None:
    if not (math.isfinite(tau) and tau > 0):
        raise ValueError(f"tau must be a positive finite time in s, got {tau}")
    if not 0.0 < ratio <= 1.0:
        raise ValueError(f"ratio E_inf/E_0 must be in (0, 1], got {ratio}")


@dataclass(frozen=True)
class StandardLinearSolid:
    """Relaxation of one sample: time constant ``tau`` (s, > 0) and ``ratio`` = E_inf / E_0."""

    tau: float
    ratio: float
    form = "sls"

    def __post_init__(self) -> None:
        _checked(self.tau, self.ratio)

    def relaxation(self, t: ArrayLike) -> FloatArray:
        """G(t) = r + (1 - r) exp(-t/tau) for t >= 0."""
        tt = np.asarray(t, dtype=np.float64)
        return self.ratio + (1.0 - self.ratio) * np.exp(-tt / self.tau)

    @property
    def prony(self) -> Prony:
        return Prony(self.ratio, (self.tau,), (1.0 - self.ratio,))

    def weights(self, dt: float) -> tuple[float, float]:
        """(decay, gain) of a step dt >= 0: exp(-dt/tau) and (tau/dt)(1 - exp(-dt/tau))."""
        decay, gain = self.prony.step_weights(dt)
        return float(decay[0]), float(gain[0])

    def describe(self) -> dict[str, object]:
        return {"form": self.form, "relaxation_time_s": self.tau, "relaxed_ratio": self.ratio}


@dataclass(frozen=True)
class PowerLawSolid:
    """``G(t) = ratio + (1 - ratio) (1 + t/tau)^-exponent``: tau (s) > 0, 0 < exponent <= 3."""

    tau: float
    ratio: float
    exponent: float
    form = "power-law"

    def __post_init__(self) -> None:
        _checked(self.tau, self.ratio)
        if not 0.0 < self.exponent <= 3.0:
            raise ValueError(f"exponent must be in (0, 3], got {self.exponent}")

    def relaxation(self, t: ArrayLike) -> FloatArray:
        tt = np.asarray(t, dtype=np.float64)
        return self.ratio + (1.0 - self.ratio) * (1.0 + tt / self.tau) ** -self.exponent

    @property
    def prony(self) -> Prony:
        return power_law_prony(self.tau, self.ratio, self.exponent)

    def describe(self) -> dict[str, object]:
        return {
            "form": self.form,
            "relaxation_time_s": self.tau,
            "relaxed_ratio": self.ratio,
            "exponent": self.exponent,
        }


Relaxation = StandardLinearSolid | PowerLawSolid


@lru_cache(maxsize=64)
def power_law_prony(tau: float, ratio: float, exponent: float) -> Prony:
    """The Prony series of :class:`PowerLawSolid` (see the module docstring): non-negative
    weights on fixed times, fitted to ``(1 + t/tau)^-exponent`` in relative error (t = 0 held
    to G(0) = 1), then scaled by ``1 - ratio``."""
    lo, hi = PRONY_SPAN_S
    n = round(math.log10(hi / lo) * PRONY_PER_DECADE) + 1
    taus = np.geomspace(lo, hi, n)
    t = np.concatenate([[0.0], np.geomspace(lo / 10.0, hi / 10.0, 12 * n)])
    g = (1.0 + t / tau) ** -exponent
    a = np.exp(-t[:, None] / taus[None, :]) / g[:, None]
    rhs = np.ones_like(t)
    a[0] *= 100.0  # G(0) = 1 held tightly: the instantaneous modulus is E_0
    rhs[0] *= 100.0
    w, _ = nnls(a, rhs, maxiter=50 * n)
    w *= 1.0 / w.sum()
    keep = w > 0
    return Prony(ratio, tuple(taus[keep].tolist()), tuple(((1.0 - ratio) * w[keep]).tolist()))


@dataclass(frozen=True)
class ViscoelasticState:
    """What one trial carries from step to step: the last elastic force and the memories (N),
    one per Prony term (empty: all zero)."""

    elastic_force: float = 0.0
    memory: tuple[float, ...] = ()

    def memories(self, n: int) -> FloatArray:
        return np.zeros(n) if not self.memory else np.asarray(self.memory, dtype=np.float64)


def step(
    relax: Relaxation, law: ElasticLaw, state: ViscoelasticState, delta: float, dt: float
) -> tuple[float, float, ViscoelasticState]:
    """Advance by ``dt`` (s) to depth ``delta`` (m): (force N, dF/ddelta N/m at this step, state).

    The stiffness is that of the step's force against its end depth (what a Newton iteration on
    the depth needs): ``(r + sum_k w_k gain_k) dF_e/ddelta``.
    """
    p = relax.prony
    decay, gain = p.step_weights(dt)
    w = np.asarray(p.weights)
    fe, ke = law.force_and_stiffness_at(delta)
    memory = decay * state.memories(w.size) + gain * (fe - state.elastic_force)
    force = p.ratio * fe + float(w @ memory)
    stiffness = (p.ratio + float(w @ gain)) * ke
    return force, stiffness, ViscoelasticState(fe, tuple(memory.tolist()))


def creep(relax: Relaxation, times: ArrayLike) -> FloatArray:
    """The reduced creep function J(t) under a load applied as a step at ``times[0]`` and then
    held: the elastic force ``F_e(delta(t))`` over the load (1 at the step, 1/r once relaxed).
    Stepped as the world steps it (each step's force is affine in F_e, so holding the load fixes
    F_e in closed form); checked against each form's closed creep in ``tests/sim``."""
    t = np.asarray(times, dtype=np.float64)
    if t.ndim != 1 or np.any(np.diff(t) < 0):
        raise ValueError("times must be a 1-D array that does not decrease")
    p = relax.prony
    w = np.asarray(p.weights)
    out = np.empty_like(t)
    fe, memory = 0.0, np.zeros(w.size)
    for i in range(t.size):
        decay, gain = p.step_weights(float(t[i] - t[i - 1]) if i else 0.0)
        # 1 = r F_e' + w . (decay h + gain (F_e' - F_e))  ->  F_e'
        carried = float(w @ (decay * memory - gain * fe))
        fe_next = (1.0 - carried) / (p.ratio + float(w @ gain))
        memory = decay * memory + gain * (fe_next - fe)
        out[i], fe = fe_next, fe_next
    return out


def force_history(
    relax: Relaxation, law: ElasticLaw, times: ArrayLike, depths: ArrayLike
) -> FloatArray:
    """Force (N) along a depth history: ``times`` (n,) increasing from the first contact, with
    ``depths`` (n,) (m, >= 0); the tissue is at rest before ``times[0]`` (force 0 there)."""
    t = np.asarray(times, dtype=np.float64)
    d = np.asarray(depths, dtype=np.float64)
    if t.shape != d.shape or t.ndim != 1:
        raise ValueError("times and depths must be 1-D arrays of the same length")
    if np.any(np.diff(t) < 0):
        raise ValueError("times must not decrease")
    out = np.empty_like(d)
    state = ViscoelasticState()
    previous = float(t[0]) if t.size else 0.0
    for i in range(t.size):
        out[i], _, state = step(relax, law, state, float(d[i]), float(t[i]) - previous)
        previous = float(t[i])
    return out
