"""The plain-float twin of the two-stage solver, for one stage position.

Why a twin: numpy costs ~1 us per operation even on 0-d arrays, so the array path takes
0.2-2 ms for one position; in plain floats the same two stages take ~15-60 us with Hertz
tissue and a closed-form beam law, up to ~0.3 ms with Sneddon + thin layer + imperfection
(dominated by the tissue inverse inside the bracketing steps); with ``estimation.beam.model.Beam``
its elastica evaluations on 0-d arrays dominate past the onset (~1 ms). The trial itself
tabulates the equilibrium on grids (:mod:`sim.contact_table`), so this path serves callers of
one position.

It follows the array path step by step (:class:`ScalarBeam` mirrors
:class:`sim.equilibrium.sides.BeamSide`, the stages mirror :mod:`sim.equilibrium.arrays`):
a change to one is a change to both.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ...estimation.beam.elastica.constants import MODE_REACTION, MODE_SHORTENING, P_CRIT
from .law import (
    DEFAULT_MAX_E_OVER_L,
    AxialLaw,
    ContactEffects,
    FloatArray,
    TissueLaw,
)
from .state import ContactState, status_message


def _as_float(x: object) -> float:
    """The one value of a scalar or one-element array."""
    return float(np.asarray(x).reshape(()))


class ScalarBeam:
    """The beam law with the effects folded in, in plain floats (see ``BeamSide``)."""

    __slots__ = ("L", "e_cr", "e_max", "ea", "g", "imperfect", "inv_k", "law", "p_cr", "w0")

    def __init__(self, law: AxialLaw, fx: ContactEffects) -> None:
        self.law = law
        self.p_cr = _as_float(law.critical_load)
        self.L = _as_float(law.length)
        self.ea = _as_float(law.axial_stiffness)
        e_max = law.max_shortening
        self.e_max = DEFAULT_MAX_E_OVER_L * self.L if e_max is None else _as_float(e_max)
        self.inv_k = 0.0 if fx.tube_stiffness is None else 1.0 / fx.tube_stiffness
        self.e_cr = self.p_cr * self.L / self.ea
        self.w0 = fx.imperfection * self.L
        self.g = MODE_SHORTENING * fx.imperfection**2 * self.L
        self.imperfect = self.g > 0

    # -- before the onset (e <= e_cr): explicit in P
    def pre_onset_shortening(self, P: float) -> float:
        e = P * self.L / self.ea
        if self.imperfect:
            q = 1.0 - P / self.p_cr
            e += self.g * (1.0 / (q * q) - 1.0)
        return e

    def pre_onset_compliance(self, P: float) -> float:
        de = self.L / self.ea
        if self.imperfect:
            q = 1.0 - P / self.p_cr
            de += 2.0 * self.g / (self.p_cr * q**3)
        return de

    # -- any e >= 0
    def onset_force(self) -> float:
        """P at the onset e = e_cr."""
        return self.imperfect_force(self.e_cr) if self.imperfect else self.p_cr

    def force(self, e: float) -> float:
        perfect = _as_float(self.law.force(np.asarray(e)))
        if not self.imperfect:
            return perfect
        return self.imperfect_force(e) + max(perfect - self.p_cr, 0.0)

    def imperfect_force(self, e: float) -> float:
        """P_imp(e), the imperfect straight-range law (Newton from the right)."""
        e_cr, g = self.e_cr, self.g
        p = min(e / e_cr, 1.0 - math.sqrt(g / (e + g)))
        for _ in range(60):
            q = 1.0 - p
            new = max(p - (e_cr * p + g * (1.0 / (q * q) - 1.0) - e) / (e_cr + 2.0 * g / q**3), 0.0)
            if abs(new - p) <= 1e-15:
                return new * self.p_cr
            p = new
        return p * self.p_cr

    def lateral(self, e: float) -> float:
        law = self.law
        R = 0.0 if law.lateral_force is None else _as_float(law.lateral_force(np.asarray(e)))
        if not self.imperfect:
            return R
        p_cr, L = self.p_cr, self.L
        amp = self.w0 / (1.0 - min(self.imperfect_force(e), p_cr * (1.0 - 1e-15)) / p_cr)
        r_imp = p_cr / P_CRIT * MODE_REACTION * (amp - self.w0) / L
        return law.reaction_sign * max(r_imp, law.reaction_sign * R)


def solve_scalar(
    u_in: FloatArray,
    law: AxialLaw,
    tissue: TissueLaw,
    fx: ContactEffects,
    atol: float,
    maxiter: int,
) -> ContactState:
    """Equilibrium at one checked stage advance (a one-element ``u_in`` and a scalar law); the
    outputs are shaped like ``u_in``."""
    u = float(u_in.reshape(()))
    beam = ScalarBeam(law, fx)
    p_a = beam.onset_force()
    d_a = tissue.inverse_at(p_a)
    u_a = d_a + beam.e_cr + p_a * beam.inv_k
    if u <= u_a:
        delta, e, P, status, it = _pre_onset(u, d_a, beam, tissue, atol, maxiter)
    else:
        delta, e, P, status, it = _post_onset(u, (p_a, d_a, u_a), beam, tissue, atol, maxiter)
    residual = u - (delta + e + P * beam.inv_k)
    converged = status == 0 and abs(residual) <= 4.0 * atol + 1e-12 * u
    if not converged and status == 0:
        status = 1

    def out(x: float) -> FloatArray:
        return np.full(u_in.shape, x, dtype=np.float64)

    return ContactState(
        delta=out(delta),
        e=out(e),
        P=out(P),
        R=out(beam.lateral(e)),
        buckled=np.full(u_in.shape, e > beam.e_cr),
        converged=np.full(u_in.shape, converged),
        success=converged,
        status=status,
        message=status_message(status, int(not converged), 1),
        iterations=it,
    )


_Stage = tuple[float, float, float, int, int]  # delta, e, P, status, iterations


def _pre_onset(
    u: float, d_a: float, beam: ScalarBeam, tissue: TissueLaw, atol: float, maxiter: int
) -> _Stage:
    """Newton in delta from the right on a convex increasing function."""
    d, lo = min(u, d_a), 0.0
    it = 0
    for it in range(1, maxiter + 1):  # noqa: B007
        f, k = tissue.force_and_stiffness_at(d)
        r = d + beam.pre_onset_shortening(f) + f * beam.inv_k - u
        if abs(r) <= atol:
            break
        if r < 0:
            lo = d
        new = d - r / (1.0 + (beam.pre_onset_compliance(f) + beam.inv_k) * k)
        d = 0.5 * (lo + d) if new < lo else new
    P = tissue.force_and_stiffness_at(d)[0]
    return d, beam.pre_onset_shortening(P), P, 0, it


def _post_onset(
    u: float,
    onset: tuple[float, float, float],
    beam: ScalarBeam,
    tissue: TissueLaw,
    atol: float,
    maxiter: int,
) -> _Stage:
    """Anderson-Bjorck on h(e) = e + delta(P(e)) + P(e)/k - u in [e_cr, e_hi]; ``onset`` is
    (P, delta, u) at e = e_cr."""
    p_a, d_a, u_a = onset
    inv_k = beam.inv_k

    def h(e: float) -> tuple[float, float]:
        P = beam.force(e)
        return e + tissue.inverse_at(max(P, 0.0)) + P * inv_k - u, P

    a, fa = beam.e_cr, u_a - u
    b = min(max(u - d_a - p_a * inv_k, beam.e_cr), beam.e_max)
    fb, p_b = h(b)
    if fb < 0:  # past the load maximum: widen
        b = min(max(u, beam.e_cr), beam.e_max)
        fb, p_b = h(b)
    status, e, P, it = 2, b, p_b, 0
    if fb >= 0:
        status = 0
        e, P, it = _anderson_bjorck(h, (a, fa), (b, fb, p_b), atol, maxiter)
    return tissue.inverse_at(max(P, 0.0)), e, P, status, it


def _anderson_bjorck(
    h: Callable[[float], tuple[float, float]],
    left: tuple[float, float],
    right: tuple[float, float, float],
    atol: float,
    maxiter: int,
) -> tuple[float, float, int]:
    """Bracketing secant from ``left`` = (a, h(a)) and ``right`` = (b, h(b), P(b)), h(b) >= 0:
    (e, P(e), iterations) at the last point tried."""
    a, fa = left
    b, fb, P = right
    x, fx = b, fb
    it = 0
    while abs(fx) > atol and abs(b - a) > 4e-16 * abs(b) and it < maxiter:
        it += 1
        c = b - fb * (b - a) / (fb - fa) if fb != fa else 0.5 * (a + b)
        if not min(a, b) < c < max(a, b):
            c = 0.5 * (a + b)
        fc, p_c = h(c)
        if (fc > 0) == (fb > 0):
            m = 1.0 - fc / fb if fb != 0 else 0.5
            fa *= m if m > 0 else 0.5
        else:
            a, fa = b, fb
        b, fb = c, fc
        x, fx, P = c, fc, p_c
    return x, P, it
