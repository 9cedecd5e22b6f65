"""Viscoelastic tissue: quasi-linear viscoelasticity (Fung) with a standard-linear-solid kernel.

The force is the elastic law's force history filtered by a reduced relaxation function::

    F(t) = integral_0^t G(t - s) dF_e(delta(s))/ds ds,    G(t) = r + (1 - r) exp(-t / tau),

with ``F_e`` the elastic law at the instantaneous modulus E_0 and ``r = E_inf / E_0`` in (0, 1]:
a fast indentation meets E_0, a slow one (or a held one, after a few tau) E_inf, so indentation
speed matters as it does on silicone and gel phantoms. Splitting ``F = r F_e + (1 - r) h``, the
memory ``h = integral exp(-(t - s)/tau) dF_e`` obeys, over a step dt in which F_e changes
linearly in time (the exact exponential recursion of a piecewise-linear input)::

    h_{n+1} = exp(-dt/tau) h_n + (tau/dt) (1 - exp(-dt/tau)) (F_e,n+1 - F_e,n),

one state per trial (the last F_e and h), O(1) per step, unconditionally stable, exact for a
force that is linear in time and second-order accurate otherwise.

Simplified: the kernel is separable (the same relaxation at every depth, as QLV assumes), and
the returned force is not clipped: when the tip retracts faster than the tissue relaxes it can
turn negative, which a caller reads as loss of contact.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]


class ElasticLaw(Protocol):
    """What the viscoelastic model needs from an elastic law (TissueModel, FeTissueLaw)."""

    def force_and_stiffness_at(self, delta: float) -> tuple[float, float]: ...


@dataclass(frozen=True)
class StandardLinearSolid:
    """Relaxation of one sample: time constant ``tau`` (s, > 0) and ``ratio`` = E_inf / E_0."""

    tau: float
    ratio: float

    def __post_init__(self) -> None:
        if not (math.isfinite(self.tau) and self.tau > 0):
            raise ValueError(f"tau must be a positive finite time in s, got {self.tau}")
        if not 0.0 < self.ratio <= 1.0:
            raise ValueError(f"ratio E_inf/E_0 must be in (0, 1], got {self.ratio}")

    def relaxation(self, t: ArrayLike) -> FloatArray:
        """G(t) = r + (1 - r) exp(-t/tau) for t >= 0."""
        tt = np.asarray(t, dtype=np.float64)
        return self.ratio + (1.0 - self.ratio) * np.exp(-tt / self.tau)

    def weights(self, dt: float) -> tuple[float, float]:
        """(decay, gain) of a step dt >= 0: exp(-dt/tau) and (tau/dt)(1 - exp(-dt/tau))."""
        if not (dt >= 0 and math.isfinite(dt)):
            raise ValueError(f"time step must be finite and >= 0, got {dt}")
        x = dt / self.tau
        decay = math.exp(-x)
        gain = -math.expm1(-x) / x if x > 0 else 1.0
        return decay, gain


@dataclass(frozen=True)
class ViscoelasticState:
    """What one trial carries from step to step: the last elastic force and the memory (N)."""

    elastic_force: float = 0.0
    memory: float = 0.0


def step(
    sls: StandardLinearSolid, law: ElasticLaw, state: ViscoelasticState, delta: float, dt: float
) -> tuple[float, float, ViscoelasticState]:
    """Advance by ``dt`` (s) to depth ``delta`` (m): (force N, dF/ddelta N/m at this step, state).

    The stiffness is that of the step's force against its end depth (what a Newton iteration on
    the depth needs): ``(r + (1 - r) gain) dF_e/ddelta``.
    """
    decay, gain = sls.weights(dt)
    fe, ke = law.force_and_stiffness_at(delta)
    memory = decay * state.memory + gain * (fe - state.elastic_force)
    r = sls.ratio
    force = r * fe + (1.0 - r) * memory
    return force, (r + (1.0 - r) * gain) * ke, ViscoelasticState(fe, memory)


def force_history(
    sls: StandardLinearSolid, law: ElasticLaw, times: ArrayLike, depths: ArrayLike
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
        out[i], _, state = step(sls, law, state, float(d[i]), float(t[i]) - previous)
        previous = float(t[i])
    return out
