"""Closed-form solutions of the first mode and their shape functions (accurate and fast share it).

A solution is fixed by three numbers per state: the modulus k, the wavenumber t and the Jacobi
argument u0 = K(k) - t at the clamp. Everything else (theta, curvature, x, y, grating means) is
then explicit, so the fast surrogate only has to interpolate those three smooth functions of e/L
and inherits the exact shape formulas, and the accurate solver only has to find k and t.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._scipy import ellipeinc, ellipj
from .errors import checked_unit_interval

FloatArray = NDArray[np.float64]

POINT_WIDTH = 1e-5
"""Below this interval length (fraction of L) a grating mean is the curvature at the midpoint.

The mean is (theta(s1) - theta(s0)) / (s1 - s0) exactly; the difference loses about
1e-16 / width of relative accuracy, while the midpoint rule errs by width**2 t**2 / 24, so 1e-5
keeps both below about 1e-10.
"""


class PostBuckling(Protocol):
    """What every solver returns: loads, tip angle and grating means (shape of ``e_over_L``)."""

    @property
    def e_over_L(self) -> FloatArray: ...
    @property
    def p(self) -> FloatArray: ...
    @property
    def r(self) -> FloatArray: ...
    @property
    def tip_angle(self) -> FloatArray: ...
    @property
    def method(self) -> str: ...
    def mean_curvature(self, s0: ArrayLike, s1: ArrayLike) -> FloatArray: ...


@dataclass(frozen=True)
class ElasticaSolution:
    """Clamped-pinned first-mode states, one per entry of ``e_over_L`` (all fields that shape).

    Attributes:
        e_over_L: end shortening e/L of the inextensible beam.
        p: axial load P L**2 / EI (compressive positive).
        r: lateral pin reaction R L**2 / EI in the sign convention of paper Eq. (7); with the beam
            bowing toward -y (our choice of the two mirror images) r <= 0.
        tip_angle: theta at the pin (rad), >= 0.
        modulus: elliptic modulus k = sin(alpha / 2), alpha the largest angle between the beam
            and the resultant force line.
        wavenumber: t = sqrt(p**2 + r**2), the length in units of the pendulum time scale.
        u0: Jacobi argument at the clamp, K(k) - t.
        method: which solver produced the state.

    The shape methods take arc positions as fractions of L (clamp 0, pin 1) and broadcast them
    with ``e_over_L`` by numpy rules: for an (N, M) table build the solution from e/L of shape
    (N, 1) and pass s of shape (M,).
    """

    e_over_L: FloatArray  # noqa: N815 - the paper's e/L
    p: FloatArray
    r: FloatArray
    tip_angle: FloatArray
    modulus: FloatArray
    wavenumber: FloatArray
    u0: FloatArray
    method: str

    def _u(self, s: FloatArray) -> FloatArray:
        return np.asarray(self.u0 + self.wavenumber * s)

    def _psi(self, sn: FloatArray) -> FloatArray:
        return np.asarray(2.0 * np.arcsin(self.modulus * sn))

    def _clamp_psi(self) -> FloatArray:
        """phi = psi(0): angle from the resultant force line to the clamp axis."""
        sn0, _, _, _ = ellipj(self.u0, self.modulus**2)
        return self._psi(sn0)

    def theta(self, s: ArrayLike) -> FloatArray:
        """Tangent angle theta(s) (rad), theta(0) = 0."""
        s_arr = checked_unit_interval(s, "s")
        sn, _, _, _ = ellipj(self._u(s_arr), self.modulus**2)
        return np.asarray(self._psi(sn) - self._clamp_psi())

    def curvature(self, s: ArrayLike) -> FloatArray:
        """Dimensionless curvature L dtheta/ds at s: 2 k t cn(u0 + t s)."""
        s_arr = checked_unit_interval(s, "s")
        _, cn, _, _ = ellipj(self._u(s_arr), self.modulus**2)
        return np.asarray(2.0 * self.modulus * self.wavenumber * cn)

    def xy(self, s: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """Centre-line position (x/L, y/L) at s; clamp at the origin, x along the clamp axis.

        Integrals of cos(psi) and sin(psi) in closed form: 2 (E(u) - E(u0)) - t s and
        -2 k (cn(u) - cn(u0)), rotated by -phi.
        """
        s_arr = checked_unit_interval(s, "s")
        m = self.modulus**2
        t = self.wavenumber
        _, cn, _, am = ellipj(self._u(s_arr), m)
        sn0, cn0, _, am0 = ellipj(self.u0, m)
        phi = self._psi(sn0)
        along = 2.0 * (ellipeinc(am, m) - ellipeinc(am0, m)) - t * s_arr  # integral of cos(psi)
        across = -2.0 * self.modulus * (cn - cn0)  # integral of sin(psi)
        x = (np.cos(phi) * along + np.sin(phi) * across) / t
        y = (np.cos(phi) * across - np.sin(phi) * along) / t
        return np.asarray(x), np.asarray(y)

    def x(self, s: ArrayLike) -> FloatArray:
        """x(s)/L; x(1) = 1 - e/L."""
        return self.xy(s)[0]

    def y(self, s: ArrayLike) -> FloatArray:
        """y(s)/L; y(1) = 0 (the pin is on the clamp axis); y <= 0 near the clamp."""
        return self.xy(s)[1]

    def mean_curvature(
        self, s0: ArrayLike, s1: ArrayLike, *, point_width: float = POINT_WIDTH
    ) -> FloatArray:
        """Mean of L dtheta/ds over s in [s0, s1] (fractions of L), paper Eq. (12) without dy_fbg.

        Exactly (theta(s1) - theta(s0)) / (s1 - s0), so no quadrature; the order of s0 and s1
        does not matter. Intervals shorter than ``point_width`` return the midpoint curvature.
        Shape: numpy broadcast of ``e_over_L``, ``s0`` and ``s1``.
        """
        a = checked_unit_interval(s0, "s0")
        b = checked_unit_interval(s1, "s1")
        m = self.modulus**2
        sn_a, _, _, _ = ellipj(self._u(a), m)
        sn_b, _, _, _ = ellipj(self._u(b), m)
        width = b - a
        wide = np.abs(width) > point_width
        mean = (self._psi(sn_b) - self._psi(sn_a)) / np.where(wide, width, 1.0)
        if np.all(wide):
            return np.asarray(mean)
        _, cn_mid, _, _ = ellipj(self._u(0.5 * (a + b)), m)
        point = 2.0 * self.modulus * self.wavenumber * cn_mid
        return np.asarray(np.where(wide, mean, point))
