"""The contact of a viscoelastic sample, stepped on the virtual clock.

A viscoelastic tissue's force depends on its history, so the equilibrium cannot be tabulated
over the stage advance as :mod:`sim.contact_table` does for elastic samples: here it is solved
at every board sample, one quasi-linear-viscoelastic state per trial (:mod:`sim.viscoelastic`).
Over a step ``dt`` the relaxation's force (a Prony series, whichever form) is an affine map of
the elastic law (:class:`StepLaw`)::

    F(delta) = a F_e(delta) + b,   a = r + sum_k w_k gain_k,
                                   b = sum_k w_k (decay_k h_k - gain_k F_e,prev)

so the step's equilibrium is the ordinary one (:func:`sim.equilibrium.solve_contact`, its
plain-float path) with that law, and the state moves on with the solved depth. Out of contact
the memory relaxes toward ``F_e = 0`` (the surface recovers while the tip is away).

Simplified: the force is clipped at 0 (no adhesion; where ``b < 0`` the law has a gap: the
surface has not yet recovered from the last indentation) and ``b`` is not allowed above 0 (a
tissue does not push on a tip that does not indent it). Cost: one scalar solve per board sample
(~0.1-1 ms with the elastica beam), against a table lookup on the elastic path.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..estimation.beam.model import Beam
from .contact_table import GridPhysics, grating_strains
from .equilibrium import TissueLaw, solve_contact
from .equilibrium.law import FloatArray
from .viscoelastic import Relaxation, ViscoelasticState, step

Row = tuple[float, float, float, float, tuple[float, ...]]  # delta, e, P, |R|, strains


@dataclass(frozen=True)
class StepLaw:
    """The tissue law over one step of the clock: ``max(a F_e(delta) + b, 0)`` (a > 0, b <= 0)."""

    elastic: TissueLaw
    a: float
    b: float

    def force_and_stiffness(self, delta: ArrayLike) -> tuple[FloatArray, FloatArray]:
        f, k = self.elastic.force_and_stiffness(delta)
        g = self.a * f + self.b
        return np.maximum(g, 0.0), np.where(g > 0, self.a * k, 0.0)

    def inverse(self, force: ArrayLike) -> FloatArray:
        f = np.asarray(force, dtype=np.float64)
        return self.elastic.inverse(np.maximum((f - self.b) / self.a, 0.0))

    def force_and_stiffness_at(self, delta: float) -> tuple[float, float]:
        f, k = self.elastic.force_and_stiffness_at(delta)
        g = self.a * f + self.b
        return (g, self.a * k) if g > 0 else (0.0, 0.0)

    def inverse_at(self, force: float) -> float:
        return self.elastic.inverse_at(max((force - self.b) / self.a, 0.0))


def step_law(relax: Relaxation, elastic: TissueLaw, state: ViscoelasticState, dt: float) -> StepLaw:
    """The force law of the step ``dt`` (s) from ``state`` (see the module docstring)."""
    p = relax.prony
    decay, gain = p.step_weights(dt)
    w = np.asarray(p.weights)
    b = float(w @ (decay * state.memories(w.size) - gain * state.elastic_force))
    return StepLaw(elastic, p.ratio + float(w @ gain), min(b, 0.0))


class ViscoelasticContact:
    """One trial's viscoelastic contact: :meth:`at` a board sample in contact, :meth:`release`
    one out of contact; both step the state from the previous sample's time."""

    def __init__(self, physics: GridPhysics, sls: Relaxation) -> None:
        self.physics = physics
        self.sls = sls
        self.state = ViscoelasticState()
        self._t: float | None = None

    def _dt(self, t: float) -> float:
        dt = 0.0 if self._t is None else max(t - self._t, 0.0)
        self._t = t
        return dt

    def at(self, t: float, u: float, length: float) -> Row:
        """The equilibrium at time ``t`` (s) and advance ``u`` past contact (m) for exposed
        length ``length`` (m). Raises RuntimeError naming the failure if it does not converge."""
        p = self.physics
        dt = self._dt(t)
        law = step_law(self.sls, p.tissue, self.state, dt)
        beam = Beam(p.EI, p.EA, p.fiber_offset, length)
        sol = solve_contact(u, beam, law, p.effects)
        if not sol.success:
            raise RuntimeError(
                f"viscoelastic contact failed at t = {t:.6g} s, L = {length:.6g} m: {sol.message}"
            )
        delta = float(sol.delta)
        _, _, self.state = step(self.sls, p.tissue, self.state, delta, dt)
        P, R = np.atleast_1d(sol.P), np.abs(np.atleast_1d(sol.R))
        strains = grating_strains(p, beam, P, R)[0]
        return delta, float(sol.e), float(P[0]), float(R[0]), tuple(strains.tolist())

    def release(self, t: float) -> None:
        """Out of contact at time ``t``: the memory relaxes toward an unloaded tissue."""
        dt = self._dt(t)
        if self.state.elastic_force != 0.0 or any(self.state.memory):
            _, _, self.state = step(self.sls, self.physics.tissue, self.state, 0.0, dt)
            if max(map(abs, self.state.memory), default=0.0) <= 1e-15:
                self.state = ViscoelasticState()
