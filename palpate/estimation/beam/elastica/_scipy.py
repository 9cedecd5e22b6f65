"""Typed facade over the few scipy routines the mechanics use.

scipy ships no type information (no ``py.typed``, no stubs in the dev dependencies), so under
``mypy --strict`` every scipy call would leak ``Any``. This module is the one place that imports
scipy untyped and states the shapes and types we rely on; everything else imports from here.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import optimize as _optimize  # type: ignore[import-untyped,unused-ignore]
from scipy import special as _special  # type: ignore[import-untyped,unused-ignore]

FloatArray = NDArray[np.float64]


def ellipj(u: ArrayLike, m: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Jacobi sn, cn, dn and the amplitude am(u | m), broadcast over ``u`` and ``m``."""
    sn, cn, dn, ph = _special.ellipj(u, m)
    return (
        np.asarray(sn, dtype=float),
        np.asarray(cn, dtype=float),
        np.asarray(dn, dtype=float),
        np.asarray(ph, dtype=float),
    )


def ellipk(m: ArrayLike) -> FloatArray:
    """Complete elliptic integral of the first kind K(m), parameter m = k**2."""
    return np.asarray(_special.ellipk(m), dtype=float)


def ellipeinc(phi: ArrayLike, m: ArrayLike) -> FloatArray:
    """Incomplete elliptic integral of the second kind E(phi | m), any real amplitude."""
    return np.asarray(_special.ellipeinc(phi, m), dtype=float)


def elliprd(x: ArrayLike, y: ArrayLike, z: ArrayLike) -> FloatArray:
    """Carlson's symmetric integral R_D(x, y, z)."""
    return np.asarray(_special.elliprd(x, y, z), dtype=float)


def brentq(
    f: Callable[[float], float], a: float, b: float, *, xtol: float, rtol: float, maxiter: int
) -> tuple[float, bool, int, str]:
    """Bracketed scalar root: (root, converged, iterations, flag); does not raise on failure."""
    root, info = _optimize.brentq(
        f, a, b, xtol=xtol, rtol=rtol, maxiter=maxiter, full_output=True, disp=False
    )
    return float(root), bool(info.converged), int(info.iterations), str(info.flag)


def least_squares(fun: Callable[[FloatArray], FloatArray], x0: FloatArray, **kwargs: Any) -> Any:
    """``scipy.optimize.least_squares``; the result is scipy's OptimizeResult."""
    return _optimize.least_squares(fun, x0, **kwargs)


def solve_ivp(
    fun: Callable[..., Any], t_span: tuple[float, float], y0: ArrayLike, **kwargs: Any
) -> Any:
    """``scipy.integrate.solve_ivp``; the result is scipy's OdeResult.

    Imported on first use: scipy.integrate costs about 0.1 s to import and only the shooting
    baseline needs it.
    """
    from scipy import integrate  # type: ignore[import-untyped,unused-ignore]

    return integrate.solve_ivp(fun, t_span, y0, **kwargs)
