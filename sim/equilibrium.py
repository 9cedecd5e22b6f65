"""Quasi-static equilibrium of the sensor beam pressed on tissue, along the sensor axis.

After contact, a stage advance ``u`` (m) splits into tissue indentation ``delta``, beam end
shortening ``e`` and, when the tube tip is compliant, tube-tip deflection ``P / k_tube``::

    u = delta + e + P / k_tube,        F_tissue(delta) = P_beam(e) = P

The beam law is an ``estimation.beam.Beam`` (pre-buckling ``EA e / L``, then the extensible
clamped-pinned elastica) or an :class:`AxialLaw` built around any ``force(e)`` callable.

How it is solved (and why). ``u(e)`` is increasing on the rising branch, but near the buckling
plateau ``P`` barely changes while ``e`` grows, so the unknown is never ``P``:

- before the onset (``u <= u_onset``, all compression of the straight beam) the beam side is
  explicit in ``P``: ``e_b(P) = P L / EA`` (+ the imperfection's geometric shortening), so the
  unknown is ``delta`` and ``q(delta) = delta + e_b(F(delta)) + F(delta)/k - u`` is convex and
  increasing: Newton started right of the root converges monotonically, no inner solve;
- after the onset the unknown is ``e`` in the bracket ``[e_cr, u - delta_onset - P_onset/k]``
  (``P >= P_onset`` there, so the right end is never left of the root), solved by the
  Anderson-Bjorck bracketing secant; ``P`` is nearly constant, so ``h(e)`` is nearly linear
  with slope ~1 and 2-4 steps suffice.

Everything is elementwise on arrays shaped like ``u``: a whole trial's stage positions solve in
one call, and every callable in the beam law is only ever evaluated on arrays of that shape,
so a law whose parameters are arrays of the same shape (one exposed length per stage position)
also solves in one call (~0.5-13 us per position). A single position (scalar ``u``, scalar law)
takes a plain-float twin of the same two stages (~25-60 us with Hertz tissue, up to ~0.3 ms
with Sneddon + thin layer + imperfection, dominated by the tissue inverse inside the bracketing
steps). Failures are reported per element (``converged``) and overall
(``success``, ``status``, ``message``), never as NaN.

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
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Generic, Protocol, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from estimation.elastica.constants import MODE_REACTION, MODE_SHORTENING, P_CRIT
from sim.tissue import TissueModel

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]
ForceLaw = Callable[[FloatArray], ArrayLike]

DEFAULT_MAX_E_OVER_L = 0.2
"""Largest e/L the solver searches when the beam law does not say (trials visit <= 1e-2)."""

STATUS_MESSAGES: dict[int, str] = {
    0: "converged",
    1: "iteration limit reached before the tolerance",
    2: "stage advance beyond the modelled range of the beam (e > max_shortening or past the "
    "load maximum)",
}


class BeamLike(Protocol):
    """What the solver needs from ``estimation.beam.Beam``."""

    @property
    def EA(self) -> float: ...

    @property
    def length(self) -> float: ...

    def critical_load(self) -> float: ...

    def force(self, e: FloatArray, /) -> ArrayLike: ...

    def lateral_force(self, e: FloatArray, /) -> ArrayLike: ...


@dataclass(frozen=True)
class AxialLaw:
    """The beam as the contact solver sees it.

    Attributes:
        force: ``P(e)`` (N) of the perfect beam for end shortening ``e`` (m), elementwise;
            ``axial_stiffness * e / length`` up to the onset, the rising elastica after.
        critical_load: ``P_cr`` (N); scalar, or an array shaped like the ``u`` it is solved for.
        length: exposed length ``L`` (m); same shape rule.
        axial_stiffness: ``EA`` (N); same shape rule.
        lateral_force: ``R(e)`` (N) at the pin, elementwise; ``None`` gives ``R = 0``.
        max_shortening: the largest ``e`` (m) the law accepts; ``None`` means
            ``DEFAULT_MAX_E_OVER_L * length``.
        reaction_sign: the sign ``lateral_force`` gives R in the buckling direction (+1, or -1
            for ``estimation.beam.Beam``, which reports R in paper Eq. 7's sign, <= 0); the
            imperfection's reaction is given the same sign.
    """

    force: ForceLaw
    critical_load: float | FloatArray
    length: float | FloatArray
    axial_stiffness: float | FloatArray
    lateral_force: ForceLaw | None = None
    max_shortening: float | FloatArray | None = None
    reaction_sign: float = 1.0

    @property
    def onset_shortening(self) -> FloatArray:
        """e_cr = P_cr L / EA, the end of the straight-compression range (m)."""
        return np.asarray(
            np.asarray(self.critical_load) * np.asarray(self.length) / self.axial_stiffness,
            dtype=np.float64,
        )


def axial_law(beam: BeamLike | AxialLaw) -> AxialLaw:
    """Wrap an ``estimation.beam.Beam`` (or pass an AxialLaw through).

    Takes ``beam.max_shortening()`` when the beam has it, and R's sign from Beam's convention
    (paper Eq. 7: R <= 0 in the buckling direction)."""
    if isinstance(beam, AxialLaw):
        return beam
    max_e = getattr(beam, "max_shortening", None)
    return AxialLaw(
        force=beam.force,
        critical_load=beam.critical_load(),
        length=beam.length,
        axial_stiffness=beam.EA,
        lateral_force=beam.lateral_force,
        max_shortening=float(max_e()) if callable(max_e) else None,
        reaction_sign=-1.0,
    )


@dataclass(frozen=True)
class ContactEffects:
    """Fidelity switches of the contact world; the defaults (all off) cost nothing.

    Attributes:
        tube_stiffness: axial stiffness k_tube (N/m) of the tube tip the beam is clamped in;
            ``None`` for a rigid clamp.
        imperfection: initial lateral deflection amplitude w0 / L of the beam (>= 0).
    """

    tube_stiffness: float | None = None
    imperfection: float = 0.0

    def __post_init__(self) -> None:
        if self.tube_stiffness is not None and not self.tube_stiffness > 0:
            raise ValueError(f"tube_stiffness must be > 0 N/m or None, got {self.tube_stiffness}")
        if not (math.isfinite(self.imperfection) and 0.0 <= self.imperfection < 0.1):
            raise ValueError(f"imperfection w0/L must be in [0, 0.1), got {self.imperfection}")


@dataclass(frozen=True)
class ContactState:
    """Equilibrium after contact; arrays are shaped like the stage advance ``u``.

    Attributes:
        delta: tissue indentation (m).
        e: beam end shortening (m).
        P: axial load (N), equal to the tissue force.
        R: lateral reaction at the pin (N).
        buckled: ``e`` beyond the straight-compression range ``P_cr L / EA``.
        converged: per element, the residual of ``u = delta + e + P/k`` is below tolerance.
        success: all elements converged.
        status: key of ``STATUS_MESSAGES`` for the worst element (0 when ``success``).
        message: the status text, with the count of failing elements.
        iterations: iterations of the longer of the two stages.
    """

    delta: FloatArray
    e: FloatArray
    P: FloatArray
    R: FloatArray
    buckled: BoolArray
    converged: BoolArray
    success: bool
    status: int
    message: str
    iterations: int


def solve_contact(
    u: ArrayLike,
    beam: BeamLike | AxialLaw,
    tissue: TissueModel,
    effects: ContactEffects | None = None,
    *,
    atol: float = 1e-13,
    maxiter: int = 60,
) -> ContactState:
    """Equilibrium of beam, tissue and tube for stage advances ``u`` (m, >= 0) past contact.

    Args:
        u: stage advance(s) since first contact, any shape.
        beam: the beam at its current exposed length.
        tissue: the tissue's contact law.
        effects: tube compliance and beam imperfection (default: none).
        atol: absolute tolerance (m) on ``u - (delta + e + P/k)``.
        maxiter: iteration limit of each stage.

    Returns:
        A :class:`ContactState`; check ``success`` (per element: ``converged``).

    Raises:
        ValueError: on negative or non-finite ``u``, or a non-positive tolerance.
    """
    fx = effects or ContactEffects()
    law = axial_law(beam)
    uu = np.asarray(u, dtype=np.float64)
    if not np.all(np.isfinite(uu)) or np.any(uu < 0):
        raise ValueError("stage advance u must be finite and >= 0")
    if not (atol > 0 and maxiter >= 1):
        raise ValueError("atol must be > 0 and maxiter >= 1")
    shape = np.broadcast_shapes(
        uu.shape,
        np.shape(law.critical_load),
        np.shape(law.length),
        np.shape(law.axial_stiffness),
    )
    if shape == () or (uu.size == 1 and shape == uu.shape):
        return _solve_scalar(uu, law, tissue, fx, atol, maxiter)
    uu = np.broadcast_to(uu, shape).astype(np.float64)
    beam_side = _BeamSide(law, fx, shape)
    tissue_side = _TissueSide(tissue)

    # The onset of buckling (end of the straight range) and where the stage is then.
    e_a = beam_side.e_cr
    p_a = beam_side.force(e_a)
    d_a = tissue_side.inverse(p_a)
    u_a = d_a + e_a + p_a * beam_side.inv_k
    pre = uu <= u_a

    delta = np.zeros(shape)
    e = np.zeros(shape)
    converged = np.ones(shape, dtype=bool)
    status = np.zeros(shape, dtype=np.int64)
    iterations = 0

    if np.any(pre):
        d_pre, ok, it = _solve_pre_onset(uu, pre, d_a, beam_side, tissue_side, atol, maxiter)
        p_pre = tissue_side.force(d_pre)
        delta = np.where(pre, d_pre, delta)
        e = np.where(pre, beam_side.pre_onset_shortening(p_pre), e)
        converged &= ~pre | ok
        iterations = max(iterations, it)
    post = ~pre
    if np.any(post):
        e_post, ok, oor, it = _solve_post_onset(
            uu, post, e_a, p_a, d_a, beam_side, tissue_side, atol, maxiter
        )
        e = np.where(post, e_post, e)
        converged &= pre | ok
        status = np.where(post & oor, 2, status)
        iterations = max(iterations, it)

    # Consistent outputs: P from the beam state (post) or the tissue state (pre). A side with
    # no element is not evaluated; the last iteration's evaluations are recalled, not redone.
    if not np.any(post):
        P = tissue_side.force(delta)
    elif not np.any(pre):
        P = beam_side.force(e)
        delta = tissue_side.inverse(P)
    else:
        P = np.where(pre, tissue_side.force(delta), beam_side.force(np.where(pre, e_a, e)))
        delta = np.where(pre, delta, tissue_side.inverse(P))
    residual = uu - (delta + e + P * beam_side.inv_k)
    converged &= np.abs(residual) <= 4.0 * atol + 1e-12 * uu
    status = np.where(~converged & (status == 0), 1, status)
    worst = int(status.max()) if status.size else 0
    n_bad = int(np.count_nonzero(~converged))
    message = STATUS_MESSAGES[worst]
    if n_bad:
        message = f"{message} ({n_bad} of {converged.size} stage positions)"
    return ContactState(
        delta=delta,
        e=e,
        P=P,
        R=beam_side.lateral(e, P),
        buckled=e > e_a,
        converged=converged,
        success=n_bad == 0,
        status=worst,
        message=message,
        iterations=iterations,
    )


T = TypeVar("T")


class _Recall(Generic[T]):
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


class _TissueSide:
    """The tissue law for one solve, each evaluation recalled (:class:`_Recall`)."""

    def __init__(self, tissue: TissueModel) -> None:
        self.force_and_stiffness = _Recall(tissue.force_and_stiffness)
        self.inverse = _Recall(tissue.inverse)

    def force(self, delta: FloatArray) -> FloatArray:
        return self.force_and_stiffness(delta)[0]


class _BeamSide:
    """The beam law with the effects folded in, on arrays of one shape; ``force`` and the
    imperfect part are recalled (:class:`_Recall`)."""

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
        self.force = _Recall(self._force)
        self.imperfect_force = _Recall(self._imperfect_force)

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


def _solve_pre_onset(
    u: FloatArray,
    active: BoolArray,
    d_start: FloatArray,
    beam: _BeamSide,
    tissue: _TissueSide,
    atol: float,
    maxiter: int,
) -> tuple[FloatArray, BoolArray, int]:
    """Newton in delta on q(delta) = delta + e_b(F) + F/k - u, started right of the root."""
    d = np.where(active, np.minimum(u, d_start), 0.0)
    lo = np.zeros_like(d)
    ok = ~active
    it = 0
    for it in range(1, maxiter + 1):  # noqa: B007
        f, k = tissue.force_and_stiffness(d)
        q = d + beam.pre_onset_shortening(f) + f * beam.inv_k - u
        ok = ok | (np.abs(q) <= atol)
        if np.all(ok):
            break
        lo = np.where(q < 0, d, lo)
        dq = 1.0 + (beam.pre_onset_compliance(f) + beam.inv_k) * k
        new = d - q / dq
        new = np.where(new < lo, 0.5 * (lo + d), new)
        d = np.where(ok, d, new)
    return d, ok, it


def _solve_post_onset(
    u: FloatArray,
    active: BoolArray,
    e_a: FloatArray,
    p_a: FloatArray,
    d_a: FloatArray,
    beam: _BeamSide,
    tissue: _TissueSide,
    atol: float,
    maxiter: int,
) -> tuple[FloatArray, BoolArray, BoolArray, int]:
    """Anderson-Bjorck on h(e) = e + delta(P(e)) + P(e)/k - u in [e_cr, e_hi].

    Returns (e, converged, out_of_range, iterations); inactive elements sit at e_cr."""

    def h(e: FloatArray) -> FloatArray:
        P = beam.force(e)
        return e + tissue.inverse(np.maximum(P, 0.0)) + P * beam.inv_k - u

    a = e_a.copy()
    fa = np.where(active, (d_a + e_a + p_a * beam.inv_k) - u, -1.0)
    b = np.where(active, np.clip(u - d_a - p_a * beam.inv_k, e_a, beam.e_max), e_a)
    fb = h(b)
    # Past the load maximum the right end can fall left of the root: widen to [e_cr, min(u, e_max)].
    widen = active & (fb < 0)
    if np.any(widen):
        b = np.where(widen, np.clip(u, e_a, beam.e_max), b)
        fb = np.where(widen, h(b), fb)
    out_of_range = active & (fb < 0)
    live = active & ~out_of_range
    ok = ~live | (np.abs(fb) <= atol)
    x = np.where(live, b, e_a)
    fx = np.where(live, fb, 0.0)
    it = 0
    for it in range(1, maxiter + 1):  # noqa: B007
        if np.all(ok):
            break
        denom = fb - fa
        c = np.where(denom != 0, b - fb * (b - a) / np.where(denom != 0, denom, 1.0), 0.5 * (a + b))
        c = np.where((c <= np.minimum(a, b)) | (c >= np.maximum(a, b)), 0.5 * (a + b), c)
        c = np.where(live & ~ok, c, x)
        fc = h(c)
        # Anderson-Bjorck: if the sign of the new point equals b's, shrink the old end a's value.
        same = np.sign(fc) == np.sign(fb)
        m = np.where(fb != 0, 1.0 - fc / np.where(fb != 0, fb, 1.0), 0.5)
        m = np.where(m > 0, m, 0.5)
        fa_new = np.where(same, fa * m, fb)
        a_new = np.where(same, a, b)
        upd = live & ~ok
        a = np.where(upd, a_new, a)
        fa = np.where(upd, fa_new, fa)
        b = np.where(upd, c, b)
        fb = np.where(upd, fc, fb)
        x = np.where(upd, c, x)
        fx = np.where(upd, fc, fx)
        width = np.abs(b - a)
        ok = ok | (np.abs(fx) <= atol) | (width <= 4e-16 * np.abs(b))
    return x, ok & ~out_of_range, out_of_range, it


def _solve_scalar(
    u_in: FloatArray,
    law: AxialLaw,
    tissue: TissueModel,
    fx: ContactEffects,
    atol: float,
    maxiter: int,
) -> ContactState:
    """One stage position in plain floats: the same two stages as the array path, without
    numpy's per-operation overhead on 0-d arrays (~15-40 us instead of 0.2-2 ms per call).

    The simulator steps the stage one position at a time, with a new exposed length each step,
    so this is the path a trial takes ~1000 times."""
    u = float(u_in.reshape(()))
    p_cr = float(np.asarray(law.critical_load).reshape(()))
    L = float(np.asarray(law.length).reshape(()))
    ea = float(np.asarray(law.axial_stiffness).reshape(()))
    e_max = (
        DEFAULT_MAX_E_OVER_L * L
        if law.max_shortening is None
        else float(np.asarray(law.max_shortening).reshape(()))
    )
    inv_k = 0.0 if fx.tube_stiffness is None else 1.0 / fx.tube_stiffness
    e_cr = p_cr * L / ea
    g = MODE_SHORTENING * fx.imperfection**2 * L
    imperfect = g > 0

    def p_imp(e: float) -> float:  # imperfect straight-range law, see _BeamSide
        p = min(e / e_cr, 1.0 - math.sqrt(g / (e + g)))
        for _ in range(60):
            q = 1.0 - p
            new = max(p - (e_cr * p + g * (1.0 / (q * q) - 1.0) - e) / (e_cr + 2.0 * g / q**3), 0.0)
            if abs(new - p) <= 1e-15:
                return new * p_cr
            p = new
        return p * p_cr

    def beam_force(e: float) -> float:
        perfect = float(np.asarray(law.force(np.asarray(e))).reshape(()))
        return p_imp(e) + max(perfect - p_cr, 0.0) if imperfect else perfect

    p_a = p_imp(e_cr) if imperfect else p_cr
    d_a = tissue.inverse_at(p_a)
    u_a = d_a + e_cr + p_a * inv_k
    status = 0
    it = 0
    if u <= u_a:
        # Newton in delta from the right on a convex increasing function.
        d, lo = min(u, d_a), 0.0
        for it in range(1, maxiter + 1):  # noqa: B007
            f, k = tissue.force_and_stiffness_at(d)
            e_b = f * L / ea
            de_b = L / ea
            if imperfect:
                q = 1.0 - f / p_cr
                e_b += g * (1.0 / (q * q) - 1.0)
                de_b += 2.0 * g / (p_cr * q**3)
            r = d + e_b + f * inv_k - u
            if abs(r) <= atol:
                break
            if r < 0:
                lo = d
            new = d - r / (1.0 + (de_b + inv_k) * k)
            d = 0.5 * (lo + d) if new < lo else new
        P = tissue.force_and_stiffness_at(d)[0]
        e = P * L / ea
        if imperfect:
            q = 1.0 - P / p_cr
            e += g * (1.0 / (q * q) - 1.0)
        delta = d
    else:

        def h(e: float) -> tuple[float, float]:
            P = beam_force(e)
            return e + tissue.inverse_at(max(P, 0.0)) + P * inv_k - u, P

        a, fa = e_cr, u_a - u
        b = min(max(u - d_a - p_a * inv_k, e_cr), e_max)
        fb, p_b = h(b)
        if fb < 0:  # past the load maximum: widen
            b = min(max(u, e_cr), e_max)
            fb, p_b = h(b)
        if fb < 0:
            status = 2
        x, fx_ = b, fb
        P = p_b
        while status == 0 and abs(fx_) > atol and abs(b - a) > 4e-16 * abs(b) and it < maxiter:
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
            x, fx_, P = c, fc, p_c
        e = x
        delta = tissue.inverse_at(max(P, 0.0))
    residual = u - (delta + e + P * inv_k)
    converged = status == 0 and abs(residual) <= 4.0 * atol + 1e-12 * u
    if not converged and status == 0:
        status = 1
    if law.lateral_force is None:
        R = 0.0
    else:
        R = float(np.asarray(law.lateral_force(np.asarray(e))).reshape(()))
    if imperfect:
        amp = fx.imperfection * L / (1.0 - min(p_imp(e), p_cr * (1.0 - 1e-15)) / p_cr)
        r_imp = p_cr / P_CRIT * MODE_REACTION * (amp - fx.imperfection * L) / L
        R = law.reaction_sign * max(r_imp, law.reaction_sign * R)
    message = STATUS_MESSAGES[status] + ("" if converged else " (1 of 1 stage positions)")

    def out(x: float) -> FloatArray:
        return np.full(u_in.shape, x, dtype=np.float64)

    return ContactState(
        delta=out(delta),
        e=out(e),
        P=out(P),
        R=out(R),
        buckled=np.full(u_in.shape, e > e_cr),
        converged=np.full(u_in.shape, converged),
        success=converged,
        status=status,
        message=message,
        iterations=it,
    )
