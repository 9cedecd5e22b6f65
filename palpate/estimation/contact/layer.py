"""The thin-layer law: Dimitriadis' series and the layer kernel it comes from.

Finite thickness, Dimitriadis et al. 2002 (Biophys. J. 82:2798-2810, Eq. 12), a layer of
thickness ``h`` on a rigid substrate, bonded or sliding::

    F = F_0 [1 - 2 a0/pi chi + 4 a0^2/pi^2 chi^2 - 8/pi^3 (a0^3 + 4 pi^2/15 b0) chi^3
               + 16 a0/pi^4 (a0^3 + 3 pi^2/5 b0) chi^4]

bonded:      a0 = -(1.2876 - 1.4678 nu + 1.3442 nu^2)/(1 - nu),
             b0 =  (0.6387 - 1.0277 nu + 1.5164 nu^2)/(1 - nu)
non-bonded:  a0 = -0.347 (3 - 2 nu)/(1 - nu),   b0 = 0.056 (5 - 2 nu)/(1 - nu)

For nu = 0.5 bonded the bracket is ``1 + 1.133 chi + 1.283 chi^2 + 0.769 chi^3 - 0.0975
chi^4``. The series is a small-chi expansion, published with ``chi = sqrt(R delta)/h``.

The law here (:func:`layer_coefficients`) takes the bonded coefficients as published and
replaces the non-bonded ones, which vary with nu although the exact law of a layer sliding on
a frictionless base does not (docs/tissue-fe.md): to first order in chi the layer adds a uniform
approach ``F (1 - nu^2) a0 / (pi E h)``, with ``a0`` the integral over u of ``K(u) - 1``, K the
layer's surface-compliance kernel in Hankel space (:func:`layer_kernel`; Lebedev & Ufliand
1958). For the bonded kernel this integral gives Dimitriadis' bonded a0 to 0.7 % at
nu = 0.3-0.5 (tests); for the frictionless base it is ``SLIDING_A0 = -1.1676`` at every nu,
which Dimitriadis' non-bonded a0 equals only at nu = 0.27 (at nu = 0.45 the published
first-order term is 13 % too large: the layer reads 1-3 % too stiff at chi = 0.1-0.2).
``b0`` (chi^3) is the kernel's second moment times the ratio the bonded coefficients have to
theirs (b0 / int u^2 (K - 1) du = -0.263 at nu = 0.3-0.5): ``SLIDING_B0 = 0.4161``,
within 0.5 % of the published non-bonded b0 at nu = 0.45.

``estimation.contact.law`` composes it with Hertz or Sneddon (the estimator's law) and
``sim.tissue`` differently (the closed-form world). Pure functions; bad input raises ValueError.
"""

from __future__ import annotations

import math
from typing import TypeVar

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
Coefficients = tuple[float, float, float, float]
T = TypeVar("T", float, FloatArray)

SLIDING_A0 = -1.1675768
"""a0 of a layer on a frictionless rigid base: the integral of ``layer_kernel(u, nu, False) - 1``
over u in [0, inf) (it does not depend on nu; the tests recompute it by quadrature)."""

SLIDING_B0 = 0.4160761
"""b0 of a layer on a frictionless rigid base: ``BONDED_B0_PER_MOMENT`` times the integral of
``u^2 (layer_kernel(u, nu, False) - 1)`` (-1.58153)."""

BONDED_B0_PER_MOMENT = -0.2630853
"""Dimitriadis' bonded b0 over the bonded kernel's second moment at nu = 0.5 (the ratio is
-0.262 to -0.266 over nu = 0.3-0.5)."""


def layer_kernel(u: FloatArray, poisson: float, bonded: bool) -> FloatArray:
    """K(u), u = xi h: the surface compliance of a layer of thickness h on a rigid base over that
    of a half-space, for a surface load of wavenumber xi (Lebedev & Ufliand 1958). Bonded
    (kappa = 3 - 4 nu): ``(2 kappa sinh 2u - 4u)/(2 kappa cosh 2u + 1 + kappa^2 + 4u^2)``;
    frictionless base: ``(cosh 2u - 1)/(sinh 2u + 2u)``. Both tend to 1 as u grows and to 0
    at u = 0. For u >= 0 up to ~350 (cosh overflows beyond)."""
    u = np.asarray(u, dtype=np.float64)
    if bonded:
        kappa = 3.0 - 4.0 * float(poisson)
        num = 2.0 * kappa * np.sinh(2.0 * u) - 4.0 * u
        return np.asarray(num / (2.0 * kappa * np.cosh(2.0 * u) + 1.0 + kappa**2 + 4.0 * u * u))
    with np.errstate(invalid="ignore"):  # 0/0 at u = 0, where K is 0
        k = (np.cosh(2.0 * u) - 1.0) / (np.sinh(2.0 * u) + 2.0 * u)
    return np.asarray(np.where(u > 0.0, k, 0.0))


def _check_poisson(poisson: float) -> float:
    nu = float(poisson)
    if not 0.0 <= nu <= 0.5:
        raise ValueError(f"poisson must be in [0, 0.5], got {poisson!r}")
    return nu


def layer_coefficients(poisson: float, bonded: bool) -> Coefficients:
    """(k1, k2, k3, k4) of the layer law the estimator fits and the closed-form world uses:
    Dimitriadis' bonded coefficients as published, the frictionless base's from its kernel
    (``SLIDING_A0``, ``SLIDING_B0``; see the module's docstring).

    Raises:
        ValueError: ``poisson`` outside [0, 0.5].
    """
    nu = _check_poisson(poisson)
    if bonded:
        return dimitriadis_coefficients(nu, bonded=True)
    return _bracket_coefficients(SLIDING_A0, SLIDING_B0)


def dimitriadis_coefficients(poisson: float, bonded: bool) -> Coefficients:
    """(k1, k2, k3, k4) as Dimitriadis et al. published them: the bracket is
    ``1 + k1 chi + k2 chi^2 + k3 chi^3 + k4 chi^4``.

    Raises:
        ValueError: ``poisson`` outside [0, 0.5].
    """
    nu = _check_poisson(poisson)
    if bonded:
        a0 = -(1.2876 - 1.4678 * nu + 1.3442 * nu**2) / (1.0 - nu)
        b0 = (0.6387 - 1.0277 * nu + 1.5164 * nu**2) / (1.0 - nu)
    else:
        a0 = -0.347 * (3.0 - 2.0 * nu) / (1.0 - nu)
        b0 = 0.056 * (5.0 - 2.0 * nu) / (1.0 - nu)
    return _bracket_coefficients(a0, b0)


def _bracket_coefficients(a0: float, b0: float) -> Coefficients:
    """The bracket's (k1, k2, k3, k4) from Dimitriadis' a0 and b0 (his Eq. 12)."""
    pi = math.pi
    k1 = -2.0 * a0 / pi
    k2 = 4.0 * a0**2 / pi**2
    k3 = -8.0 / pi**3 * (a0**3 + 4.0 * pi**2 / 15.0 * b0)
    k4 = 16.0 * a0 / pi**4 * (a0**3 + 3.0 * pi**2 / 5.0 * b0)
    return k1, k2, k3, k4


def dimitriadis_bracket(chi: T, k: Coefficients) -> tuple[T, T]:
    """The bracket B(chi) and dB/dchi of the published quartic (no continuation); floats or
    arrays (plain arithmetic, so the simulator's scalar path pays no numpy overhead)."""
    k1, k2, k3, k4 = k
    b = 1.0 + chi * (k1 + chi * (k2 + chi * (k3 + chi * k4)))
    db = k1 + chi * (2.0 * k2 + chi * (3.0 * k3 + chi * 4.0 * k4))
    return b, db
