""":func:`solve_contact`: the checks, then the plain-float twin for one position or the arrays."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from .arrays import solve_array
from .law import AxialLaw, BeamLike, ContactEffects, TissueLaw, axial_law
from .scalar import solve_scalar
from .state import ContactState


def solve_contact(
    u: ArrayLike,
    beam: BeamLike | AxialLaw,
    tissue: TissueLaw,
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
        return solve_scalar(uu, law, tissue, fx, atol, maxiter)
    uu = np.broadcast_to(uu, shape).astype(np.float64)
    return solve_array(uu, law, tissue, fx, atol, maxiter)
