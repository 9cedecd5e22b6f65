"""The two sides of the equilibrium on arrays: the beam with its effects folded in, the tissue.

Both evaluate their laws on arrays of one shape (the shape of the stage advance ``u``), and each
evaluation is recalled (:class:`Recall`) so that the solver's outputs reuse the last iteration's.

Imperfection (``ContactEffects.imperfection = w0 / L``): a real sensor is not straight, which is
why the paper's model deviated at small post-buckling displacement. With an initial deflection
in the fixed-pinned first mode ``phi`` of amplitude ``w0``, linear theory amplifies it to
``A = w0 / (1 - P/P_cr)``; the bending part of the end shortening is
``e_geom = c (A^2 - w0^2) / L`` with ``c = (L/2) int phi'^2 ds / max(phi)^2 = 2.5816`` for the
clamped-pinned mode ``phi = mu (1 - cos mu s/L) - mu s/L + sin mu s/L``, ``mu = 4.4934``
(``tan mu = mu``), and the pin reaction is ``R = (EI/L^2) (mu^3 / 2 pi) (A - w0)/L``. So::

    e_imp(P) = P L / EA + c (w0/L)^2 L ((1 - P/P_cr)^-2 - 1),        P < P_cr

gives ``P_imp(e)``, which rises smoothly and saturates at ``P_cr``. It is blended into the
elastica by adding the perfect beam's post-buckling excess::

    P(e) = P_imp(e) + max(P_perf(e) - P_cr, 0),     |R(e)| = max(|R_imp(e)|, |R_perf(e)|)

With ``w0 = 0``, ``P_imp(e) = min(EA e / L, P_cr)`` and both lines return the perfect model
exactly (the code takes the perfect path then). For ``w0 > 0`` the onset is smooth, ``P`` stays
below the perfect curve and approaches it as ``e`` grows (``P_imp -> P_cr``); ``R_imp`` and
``R_perf`` share the same small-deflection limit, so the max is continuous. This is an
engineering blend, not an elastica of the imperfect beam: it is meant to reproduce the smooth
onset seen in Fig. 4, not the grating strains of an imperfect beam.

The plain-float twin of :class:`BeamSide` is :class:`sim.equilibrium.scalar.ScalarBeam`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Generic, TypeVar

import numpy as np

from ...estimation.beam.elastica.constants import MODE_REACTION, MODE_SHORTENING, P_CRIT
from .law import (
    DEFAULT_MAX_E_OVER_L,
    AxialLaw,
    ContactEffects,
    FloatArray,
    TissueLaw,
)

T = TypeVar("T")


class Recall(Generic[T]):
    """A pure function of one array that returns its previous result, unchanged, when it is
    called again with the same array (same shape and bits).

    Why: the solver's outputs are the laws evaluated at the converged point, which the last
    iteration has just evaluated (and the pre-onset result is the tissue law at the last Newton
    iterate); recalling them saves 2-4 of the ~20 law evaluations of a 51-point solve, each
    ~0.1-0.5 ms of numpy call overhead. The result is the very array the law returned for the
    same input, so nothing changes by a bit (a law on arrays is not always elementwise
    independent of its batch: its iterations stop when every element converged)."""

    __slots__ = ("_fn", "_key", "_value")

    def __init__(self, fn: Callable[[FloatArray], T]) -> None:
        self._fn = fn
        self._key: tuple[str, tuple[int, ...], bytes] | None = None
        self._value: T | None = None

    def __call__(self, x: FloatArray) -> T:
        key = (x.dtype.str, x.shape, x.tobytes())
        if key != self._key or self._value is None:
            self._value = self._fn(x)
            self._key = key
        return self._value


class TissueSide:
    """The tissue law for one solve, each evaluation recalled (:class:`Recall`)."""

    def __init__(self, tissue: TissueLaw) -> None:
        self.force_and_stiffness = Recall(tissue.force_and_stiffness)
        self.inverse = Recall(tissue.inverse)

    def force(self, delta: FloatArray) -> FloatArray:
        return self.force_and_stiffness(delta)[0]


class BeamSide:
    """The beam law with the effects folded in, on arrays of one shape; ``force`` and the
    imperfect part are recalled (:class:`Recall`)."""

    def __init__(self, law: AxialLaw, fx: ContactEffects, shape: tuple[int, ...]) -> None:
        self.law = law
        self.shape = shape
        self.p_cr = np.broadcast_to(np.asarray(law.critical_load, dtype=np.float64), shape)
        self.L = np.broadcast_to(np.asarray(law.length, dtype=np.float64), shape)
        self.ea = np.broadcast_to(np.asarray(law.axial_stiffness, dtype=np.float64), shape)
        self.e_cr = self.p_cr * self.L / self.ea
        e_max = law.max_shortening
        self.e_max = np.broadcast_to(
            np.asarray(DEFAULT_MAX_E_OVER_L * self.L if e_max is None else e_max, np.float64),
            shape,
        )
        self.inv_k = 0.0 if fx.tube_stiffness is None else 1.0 / fx.tube_stiffness
        self.w0 = fx.imperfection * self.L  # initial amplitude (m)
        self.g = MODE_SHORTENING * fx.imperfection**2 * self.L  # c w0^2 / L
        self.imperfect = fx.imperfection > 0
        self.force = Recall(self._force)
        self.imperfect_force = Recall(self._imperfect_force)

    # -- before the onset (e <= e_cr): explicit in P
    def pre_onset_shortening(self, P: FloatArray) -> FloatArray:
        e = P * self.L / self.ea
        if self.imperfect:
            q = 1.0 - P / self.p_cr
            e = e + self.g * (1.0 / (q * q) - 1.0)
        return e

    def pre_onset_compliance(self, P: FloatArray) -> FloatArray:
        de = self.L / self.ea
        if self.imperfect:
            q = 1.0 - P / self.p_cr
            de = de + 2.0 * self.g / (self.p_cr * q**3)
        return de

    # -- any e >= 0
    def _force(self, e: FloatArray) -> FloatArray:
        e = np.broadcast_to(e, self.shape)
        perfect = np.asarray(self.law.force(e), dtype=np.float64)
        if not self.imperfect:
            return perfect
        return self.imperfect_force(e) + np.maximum(perfect - self.p_cr, 0.0)

    def _imperfect_force(self, e: FloatArray) -> FloatArray:
        """P_imp(e): solve e_imp(P) = e for P in [0, P_cr) (Newton on a convex function from the
        right, started at min(axial-only, geometry-only) solutions, both right of the root)."""
        p_ax = e / self.e_cr
        p_geo = 1.0 - np.sqrt(self.g / (e + self.g))
        p = np.minimum(p_ax, p_geo)
        for _ in range(60):
            q = 1.0 - p
            f = self.e_cr * p + self.g * (1.0 / (q * q) - 1.0) - e
            df = self.e_cr + 2.0 * self.g / q**3
            new = np.maximum(p - f / df, 0.0)
            if np.all(np.abs(new - p) <= 1e-15):
                p = new
                break
            p = new
        return p * self.p_cr

    def lateral(self, e: FloatArray, P: FloatArray) -> FloatArray:
        if self.law.lateral_force is None:
            r_perf = np.zeros(self.shape)
        else:
            r_perf = np.asarray(self.law.lateral_force(np.broadcast_to(e, self.shape)), np.float64)
        if not self.imperfect:
            return r_perf
        # The imperfect part is carried by P_imp = P - excess; for e <= e_cr that is all of P.
        p_imp = np.minimum(self.imperfect_force(e), self.p_cr * (1.0 - 1e-15))
        amp = self.w0 / (1.0 - p_imp / self.p_cr)
        ei_over_l2 = self.p_cr / P_CRIT
        r_imp = ei_over_l2 * MODE_REACTION * (amp - self.w0) / self.L
        sign = self.law.reaction_sign
        return sign * np.maximum(r_imp, sign * r_perf)
