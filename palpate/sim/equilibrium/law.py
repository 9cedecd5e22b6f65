"""What the equilibrium solver is given: the beam's axial law, the tissue's law and the contact
world's effects.

The beam law is an ``estimation.beam.model.Beam`` (anything shaped like :class:`BeamLike`), wrapped
by
:func:`axial_law`, or an :class:`AxialLaw` built around any ``force(e)`` callable; the tissue is
anything shaped like :class:`TissueLaw` (the closed forms of ``sim.tissue``, the finite-element
tables of ``sim.fem``, a rigid block); :class:`ContactEffects` switches on the tube tip's
compliance and the beam's imperfection.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]
ForceLaw = Callable[[FloatArray], ArrayLike]

DEFAULT_MAX_E_OVER_L = 0.2
"""Largest e/L the solver searches when the beam law does not say (trials visit <= 1e-2)."""


class TissueLaw(Protocol):
    """The tissue's force against indentation depth, as the solver calls it: ``F(delta)`` and
    ``dF/ddelta`` and the inverse ``delta(F)`` on arrays (any shape, SI), and their plain-float
    twins (the per-position path). F(0) = 0 and F increases. Implemented by the closed forms
    (``sim.tissue.TissueModel``), the finite-element law (``sim.fem``) and the oblique contact
    that wraps either (``sim.oblique.ObliqueContact``). Hashable: it is part of the keys of the
    per-process equilibrium cache (``sim.contact_table``)."""

    def force_and_stiffness(self, delta: ArrayLike, /) -> tuple[FloatArray, FloatArray]: ...

    def inverse(self, force: ArrayLike, /) -> FloatArray: ...

    def force_and_stiffness_at(self, delta: float, /) -> tuple[float, float]: ...

    def inverse_at(self, force: float, /) -> float: ...

    def __hash__(self) -> int: ...


class BeamLike(Protocol):
    """What the solver needs from ``estimation.beam.model.Beam``."""

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
            for ``estimation.beam.model.Beam``, which reports R in paper Eq. 7's sign, <= 0); the
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
    """Wrap an ``estimation.beam.model.Beam`` (or pass an AxialLaw through).

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
