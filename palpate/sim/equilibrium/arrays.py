"""The vectorised two-stage solver: every stage position of an array ``u`` in one call.

Every callable of the beam law is only ever evaluated on arrays shaped like ``u``, so a law whose
parameters are arrays of that shape (one exposed length per stage position) also solves in one
call (~0.5-13 us per position, plus ~0.1-0.5 ms per law evaluation, ~20 of them a call). The
two stages (see :mod:`sim.equilibrium`) run on the elements before and after the onset; a side
with no element is not evaluated. The plain-float twin for one position is
:mod:`sim.equilibrium.scalar`.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .law import AxialLaw, BoolArray, ContactEffects, FloatArray, TissueLaw
from .sides import BeamSide, TissueSide
from .state import ContactState, status_message


class _Onset(NamedTuple):
    """The onset of buckling (end of the straight range) and where the stage is then."""

    e: FloatArray
    P: FloatArray
    delta: FloatArray
    u: FloatArray


def solve_array(
    u: FloatArray,
    law: AxialLaw,
    tissue: TissueLaw,
    fx: ContactEffects,
    atol: float,
    maxiter: int,
) -> ContactState:
    """Equilibrium at the checked stage advances ``u`` (any shape the law broadcasts to)."""
    beam_side = BeamSide(law, fx, u.shape)
    tissue_side = TissueSide(tissue)
    e_a = beam_side.e_cr
    p_a = beam_side.force(e_a)
    d_a = tissue_side.inverse(p_a)
    onset = _Onset(e_a, p_a, d_a, d_a + e_a + p_a * beam_side.inv_k)
    pre = u <= onset.u
    delta, e, converged, status, iterations = _two_stages(
        u, pre, onset, beam_side, tissue_side, atol, maxiter
    )
    delta, P = _consistent(pre, delta, e, e_a, beam_side, tissue_side)
    residual = u - (delta + e + P * beam_side.inv_k)
    converged &= np.abs(residual) <= 4.0 * atol + 1e-12 * u
    status = np.where(~converged & (status == 0), 1, status)
    worst = int(status.max()) if status.size else 0
    n_bad = int(np.count_nonzero(~converged))
    return ContactState(
        delta=delta,
        e=e,
        P=P,
        R=beam_side.lateral(e, P),
        buckled=e > e_a,
        converged=converged,
        success=n_bad == 0,
        status=worst,
        message=status_message(worst, n_bad, converged.size),
        iterations=iterations,
    )


def _two_stages(
    u: FloatArray,
    pre: BoolArray,
    onset: _Onset,
    beam: BeamSide,
    tissue: TissueSide,
    atol: float,
    maxiter: int,
) -> tuple[FloatArray, FloatArray, BoolArray, np.ndarray, int]:
    """Both stages on their elements: (delta, e, converged, status, iterations); delta of the
    post-onset elements is left for :func:`_consistent`."""
    shape = u.shape
    delta = np.zeros(shape)
    e = np.zeros(shape)
    converged = np.ones(shape, dtype=bool)
    status = np.zeros(shape, dtype=np.int64)
    iterations = 0
    if np.any(pre):
        d_pre, ok, it = _solve_pre_onset(u, pre, onset.delta, beam, tissue, atol, maxiter)
        p_pre = tissue.force(d_pre)
        delta = np.where(pre, d_pre, delta)
        e = np.where(pre, beam.pre_onset_shortening(p_pre), e)
        converged &= ~pre | ok
        iterations = max(iterations, it)
    post = ~pre
    if np.any(post):
        e_post, ok, oor, it = _solve_post_onset(u, post, onset, beam, tissue, atol, maxiter)
        e = np.where(post, e_post, e)
        converged &= pre | ok
        status = np.where(post & oor, 2, status)
        iterations = max(iterations, it)
    return delta, e, converged, status, iterations


def _consistent(
    pre: BoolArray,
    delta: FloatArray,
    e: FloatArray,
    e_a: FloatArray,
    beam: BeamSide,
    tissue: TissueSide,
) -> tuple[FloatArray, FloatArray]:
    """Consistent outputs (delta, P): P from the beam state (post) or the tissue state (pre).

    A side with no element is not evaluated; the last iteration's evaluations are recalled,
    not redone."""
    if np.all(pre):
        return delta, tissue.force(delta)
    if not np.any(pre):
        P = beam.force(e)
        return tissue.inverse(P), P
    P = np.where(pre, tissue.force(delta), beam.force(np.where(pre, e_a, e)))
    return np.where(pre, delta, tissue.inverse(P)), P


def _solve_pre_onset(
    u: FloatArray,
    active: BoolArray,
    d_start: FloatArray,
    beam: BeamSide,
    tissue: TissueSide,
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
    onset: _Onset,
    beam: BeamSide,
    tissue: TissueSide,
    atol: float,
    maxiter: int,
) -> tuple[FloatArray, BoolArray, BoolArray, int]:
    """Anderson-Bjorck on h(e) = e + delta(P(e)) + P(e)/k - u in [e_cr, e_hi].

    Returns (e, converged, out_of_range, iterations); inactive elements sit at e_cr."""

    def h(e: FloatArray) -> FloatArray:
        P = beam.force(e)
        return e + tissue.inverse(np.maximum(P, 0.0)) + P * beam.inv_k - u

    e_a, p_a, d_a, _ = onset
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
        c = _secant_point(a, fa, b, fb)
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


def _secant_point(a: FloatArray, fa: FloatArray, b: FloatArray, fb: FloatArray) -> FloatArray:
    """The secant step through (a, fa) and (b, fb), or the midpoint where it leaves (a, b)."""
    denom = fb - fa
    c = np.where(denom != 0, b - fb * (b - a) / np.where(denom != 0, denom, 1.0), 0.5 * (a + b))
    return np.where((c <= np.minimum(a, b)) | (c >= np.maximum(a, b)), 0.5 * (a + b), c)
