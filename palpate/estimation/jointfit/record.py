"""The joint fit's input: a loading record checked once, and the checks of the fit's options."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class Record:
    """A loading record, checked: every array (N,), finite, SI units.

    Attributes:
        advance: stage positions u (m).
        force: axial loads P (N) inferred from the strains.
        depth_base: u - e (m), e the beam's end shortening: the indentation at contact position
            x0 is ``depth_base - x0``.
        sigma_force: standard deviations of P (N, > 0).
        sigma_shortening: standard deviations of e (m, >= 0).
    """

    advance: FloatArray
    force: FloatArray
    depth_base: FloatArray
    sigma_force: FloatArray
    sigma_shortening: FloatArray

    @property
    def n(self) -> int:
        """N, the number of samples."""
        return self.advance.size

    def depth_base_at(self, compliance: float) -> FloatArray:
        """u - e - c P (m): ``depth_base`` with the rig's compliance c (m/N) taken out, the
        clamp having moved back by c P under the load P."""
        if compliance == 0.0:
            return self.depth_base
        return np.asarray(self.depth_base - compliance * self.force)


def checked_record(
    advance: ArrayLike,
    force: ArrayLike,
    shortening: ArrayLike,
    sigma_force: ArrayLike,
    sigma_shortening: ArrayLike,
) -> Record:
    """The record as (N,) float arrays (scalars broadcast); ValueError naming the bad array."""
    u = _vector("advance", advance, None)
    n = u.size
    P = _vector("force", force, n)
    e = _vector("shortening", shortening, n)
    sig_p = _vector("sigma_force", sigma_force, n)
    sig_e = _vector("sigma_shortening", sigma_shortening, n)
    if np.any(sig_p <= 0) or np.any(sig_e < 0):
        raise ValueError("sigma_force must be > 0 and sigma_shortening >= 0")
    return Record(u, P, u - e, sig_p, sig_e)


def check_options(
    confidence: float, search: float, f_scale: float, encoder_resolution: float
) -> None:
    """ValueError unless 0 < confidence < 1, search >= 0 (finite), f_scale > 0, q >= 0."""
    if not (0.0 < confidence < 1.0):
        raise ValueError(f"confidence must be in (0, 1), got {confidence!r}")
    if not (math.isfinite(search) and search >= 0 and f_scale > 0 and encoder_resolution >= 0):
        raise ValueError("search must be >= 0, f_scale > 0, encoder_resolution >= 0")


def _vector(name: str, value: ArrayLike, n: int | None) -> FloatArray:
    arr = np.asarray(value, dtype=np.float64)
    if n is not None:
        if arr.ndim > 1 or arr.size not in (1, n):
            raise ValueError(f"{name} must have {n} values (one per sample), got {arr.shape}")
        arr = np.broadcast_to(arr, (n,))
    if arr.ndim != 1 or not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be a finite 1-D array (or a scalar), got shape {arr.shape}")
    return arr
