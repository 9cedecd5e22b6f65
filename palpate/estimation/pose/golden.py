"""Golden-section search on many independent minima at once (the loads' lean fits:
``estimation.pose.misalignment``, ``estimation.pose.slip_path``).

Each step keeps the interior point the bracket still holds and evaluates only the new one, so
``steps`` steps cost ``steps + 1`` calls of ``f``::

    lo, hi = golden_brackets(lambda x: (x - target) ** 2, lo, hi, steps=20)
    best = 0.5 * (lo + hi)
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

PHI = (math.sqrt(5.0) - 1.0) / 2.0


def golden_brackets(
    f: Callable[[FloatArray], FloatArray], lo: FloatArray, hi: FloatArray, steps: int
) -> tuple[FloatArray, FloatArray]:
    """The brackets [lo, hi] of the minima of ``f`` (elementwise: each element of its argument
    and result is its own search) after ``steps`` golden-section steps.

    >>> lo, hi = golden_brackets(lambda x: (x - 0.3) ** 2, np.zeros(1), np.ones(1), 30)
    >>> round(float(0.5 * (lo + hi)[0]), 6)
    0.3
    """
    a, b = hi - PHI * (hi - lo), lo + PHI * (hi - lo)
    fa, fb = f(a), f(b)
    for _ in range(steps - 1):
        left = fa < fb
        lo, hi = np.where(left, lo, a), np.where(left, b, hi)
        new = np.where(left, hi - PHI * (hi - lo), lo + PHI * (hi - lo))
        f_new = f(new)
        a, b = np.where(left, new, b), np.where(left, a, new)
        fa, fb = np.where(left, f_new, fb), np.where(left, fa, f_new)
    left = fa < fb
    return np.where(left, lo, a), np.where(left, b, hi)
