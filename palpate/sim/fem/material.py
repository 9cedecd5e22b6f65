"""Stress and tangent of the layer's materials in the axisymmetric mixed (u-p) setting.

The displacement gradient of an axisymmetric field (u_r(r, z), u_z(r, z)) has five non-zero
components, stored as a 5-vector ``H = (du_r/dr, du_r/dz, du_z/dr, du_z/dz, u_r/r)`` (the last
one is the hoop strain); the deformation gradient is ``F = I + H`` with ``I = (1, 0, 0, 1, 1)``.

Each material is a pair of functions of ``H``: an isochoric energy ``W(H)`` and a volume measure
``V(H)`` that the pressure p constrains in the two-field energy

    Pi(u, p) = integral [ W(H) + p V(H) - p^2 / (2 K) ] dV,

which is stationary at equilibrium and stays well posed at K = infinity (nu = 0.5): no locking.

- ``linear``: W = mu |dev eps|^2, V = tr eps (eps the symmetric part of H): Hooke's law,
  sigma = 2 mu dev eps + K tr eps I.
- ``neo-hookean``: W = mu/2 (J^(-2/3) I1 - 3), V = J - 1 (Simo-Taylor; the volumetric energy
  K/2 (J - 1)^2): at small strain it is the linear law with the same mu and K.

A :class:`Response` holds dW/dH, d2W/dH2, V, dV/dH and d2V/dH2 at every quadrature point, with
shapes (5, ...), (5, 5, ...), (...), (5, ...), (5, 5, ...).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

IDENTITY = np.array([1.0, 0.0, 0.0, 1.0, 1.0])
_RR, _RZ, _ZR, _ZZ, _TT = range(5)


class Response(NamedTuple):
    """Derivatives of the energy and of the volume measure at the quadrature points."""

    stress: FloatArray
    tangent: FloatArray
    volume: FloatArray
    volume_grad: FloatArray
    volume_hess: FloatArray


def _linear_tangent(shear: float) -> FloatArray:
    """d2W/dH2 of W = mu |dev eps|^2 (constant, 5 x 5)."""
    d = np.zeros((5, 5))
    normal = [_RR, _ZZ, _TT]
    for i in normal:
        d[i, i] = 2.0 * shear
        for j in normal:
            d[i, j] -= 2.0 * shear / 3.0
    d[np.ix_([_RZ, _ZR], [_RZ, _ZR])] = shear  # 2 eps_rz^2 = (H_rz + H_zr)^2 / 2
    return d


def linear(H: FloatArray, shear: float) -> Response:
    """Small-strain Hooke's law (deviatoric part; the pressure carries the volume)."""
    d = _linear_tangent(shear)
    tail = (1,) * (H.ndim - 1)
    stress = np.einsum("ij,j...->i...", d, H)
    grad = np.broadcast_to(IDENTITY.reshape((5, *tail)), H.shape)  # d tr(eps) / dH
    volume = H[_RR] + H[_ZZ] + H[_TT]
    tangent = np.broadcast_to(d.reshape((5, 5, *tail)), (5, 5, *H.shape[1:]))
    hess = np.zeros((5, 5, *H.shape[1:]))
    return Response(stress, tangent, volume, grad, hess)


def _jacobian(F: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """J = det F and its first and second derivatives with respect to the 5 components."""
    a, b, c, d, t = F
    planar = a * d - b * c
    J = planar * t
    grad = np.stack([d * t, -c * t, -b * t, a * t, planar])
    hess = np.zeros((5, 5, *J.shape))
    for (i, j), value in {
        (_RR, _ZZ): t,
        (_RZ, _ZR): -t,
        (_RR, _TT): d,
        (_ZZ, _TT): a,
        (_RZ, _TT): -c,
        (_ZR, _TT): -b,
    }.items():
        hess[i, j] = value
        hess[j, i] = value
    return J, grad, hess


def neo_hookean(H: FloatArray, shear: float) -> Response:
    """Compressible neo-Hookean solid, isochoric/volumetric split (mixed form).

    With phi = J^(-2/3) and m = dJ/J: W = mu/2 (phi I1 - 3),
    dW = mu (phi F - phi I1/3 m), d2W = mu (phi 1 - 2/3 phi (m F + F m) + I1/2 d2phi),
    d2phi = -2/3 phi (d2J/J - 5/3 m m). Raises FloatingPointError where J <= 0.
    """
    tail = (1,) * (H.ndim - 1)
    F = H + IDENTITY.reshape((5, *tail))
    J, dJ, d2J = _jacobian(F)
    if np.any(J <= 0.0):
        raise FloatingPointError("element inverted (det F <= 0)")
    phi = J ** (-2.0 / 3.0)
    m = dJ / J
    I1 = (F * F).sum(axis=0)
    stress = shear * phi * (F - I1 / 3.0 * m)
    mm = m[:, None] * m[None, :]
    d2phi = -2.0 / 3.0 * phi * (d2J / J - 5.0 / 3.0 * mm)
    eye = np.eye(5).reshape((5, 5, *tail))
    mF = m[:, None] * F[None, :]
    tangent = shear * (
        phi * eye - 2.0 / 3.0 * phi * (mF + np.swapaxes(mF, 0, 1)) + 0.5 * I1 * d2phi
    )
    return Response(stress, tangent, J - 1.0, dJ, d2J)


MaterialLaw = Callable[[FloatArray, float], Response]

MATERIAL_LAWS: dict[str, MaterialLaw] = {"linear": linear, "neo-hookean": neo_hookean}
"""Registry: material name -> response function (H, mu) -> Response."""

CONSTANT_TANGENT = frozenset({"linear"})
"""Materials whose tangent and volume gradient do not depend on H (one solve per active set)."""
