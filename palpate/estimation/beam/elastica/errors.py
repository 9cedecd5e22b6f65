"""Errors and input checks shared by the elastica solvers."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray


class ElasticaConvergenceError(RuntimeError):
    """A solver did not converge; the message names the solver, the input and the failed step."""


def checked_e_over_L(
    e_over_L: ArrayLike, e_max: float, name: str = "e_over_L"
) -> NDArray[np.float64]:
    """``e_over_L`` as floats, or ValueError naming ``name`` if an entry is not in [0, e_max].

    NaN and inf are rejected explicitly: a NaN would otherwise pass every comparison silently.
    """
    arr = np.asarray(e_over_L, dtype=float)
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite, got {_first_bad(arr, ~np.isfinite(arr))}")
    if np.any(arr < 0.0):
        raise ValueError(f"{name} must be >= 0 (end shortening), got {_first_bad(arr, arr < 0.0)}")
    if np.any(arr > e_max):
        raise ValueError(
            f"{name} must be <= {e_max!r} (end of the supported first-mode branch, where the axial "
            f"load reaches 0), got {_first_bad(arr, arr > e_max)}"
        )
    return arr


def checked_unit_interval(s: ArrayLike, name: str) -> NDArray[np.float64]:
    """Arc position ``s`` (fraction of the length, clamp 0 to pin 1) as floats, or ValueError."""
    arr = np.asarray(s, dtype=float)
    bad = ~np.isfinite(arr) | (arr < 0.0) | (arr > 1.0)
    if np.any(bad):
        raise ValueError(
            f"{name} must be a fraction of the length in [0, 1], got {_first_bad(arr, bad)}"
        )
    return arr


def _first_bad(arr: NDArray[np.float64], bad: NDArray[np.bool_]) -> float:
    return float(arr[bad].flat[0]) if arr.ndim else float(arr)
