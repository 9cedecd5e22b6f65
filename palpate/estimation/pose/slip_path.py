"""The misalignment of a slipping contact, measured from the tip's path: strains and stage.

When the tip slides on an oblique surface (``estimation.pose.misalignment`` detects it), the free
tip
deflects sideways by ``w`` while the stage advances it by ``u`` along the sensor axis. The tip
sphere's centre stays on the indented surface, so its depth along the normal, at an angle psi
to the axis, is ``delta_n = (u - x0 - e) cos(psi) - w sin(psi)``, e the beam's own shortening
(``P L / EA`` and the bow ``1/2 int y'^2``). Solved for the advance::

    u = x0 + e + delta_n / cos(psi) + w tan(psi)

The angle does not depend on the friction (the lean of the load, ``psi - atan(mu)``, does) nor
on the modulus: ``w tan(psi)`` is geometry. The normal depth follows the load; Hertz's
``delta_n ~ P^(2/3)`` is its shape here (a linear term ``B P^(2/3)`` with B free: the modulus,
the friction and the contact's effective radius all sit in B). Near the free tip's capacity
``(pi/2)^2 EI / L^2`` the load barely grows while w does, which is what separates the two terms.

The strains give ``w`` and ``P``: a clamped beam-column with ``c = tan(lean)`` across its tip
load bends as ``kappa(d) = c k sin(k d) / cos(k L)``
(``estimation.pose.misalignment.lateral_shape``)
and its tip deflects ``w = c (tan kL - kL) / k``; per row the load that fits the gratings (no
bow of a pinned beam: the tip is free) gives both. For each lean ``c`` on a grid the rows'
loads are fitted, then ``(x0, B, tan psi)`` by linear least squares on the advances; the lean is
the one the strains and the advances fit best together (each in its own noise variance). The
angle's 1-sigma: the least squares' own, widened by the residual's scatter, the spread of
tan(psi) over the leans within one unit of chi^2, and ``MODEL_FLOOR`` in quadrature.

One fiber sees one component: ``w`` is the deflection in the fiber's bending plane, ``s w`` of
a slide at an angle acos(s) to it, so the angle read is at least ``atan(tan(psi) / |s|)`` (the
bow, from the lean seen, falls short too): exact when the slide lies in the fiber's plane (a
straight tube rolled to the tilt, any bent tube's roll on a tilt along its cone), an upper bound
otherwise (8 and 16 deg read 15 and 25 deg at 45 deg off the plane). Shapes: N rows, G
gratings.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..beam.column import capacity, lateral_shape
from .golden import golden_brackets
from .misalignment import LOAD_SHARE

FloatArray = NDArray[np.float64]

MAX_BENDING = 1800e-6  # strain: the linear beam-column's slopes stay below ~0.1 rad here
MIN_BENDING = 30e-6  # strain: rows bent less are before the touch or at the noise
MIN_ROWS = 12
MAX_ROWS = 160
MODEL_FLOOR = math.radians(0.5)  # rad: the normal depth's law (Hertz's 2/3 power) and the
# linear beam-column, measured against the world's slipping contacts (docs/oblique.md)
LEAN_GRID = np.radians(np.concatenate([-np.geomspace(40.0, 0.25, 40), np.geomspace(0.25, 40, 40)]))
_CANDIDATES = 160  # loads per row below LOAD_SHARE of the capacity
_GOLDEN = 24


@dataclass(frozen=True)
class SlipPath:
    """The misalignment of a slipping contact from the tip's path.

    Attributes:
        success: the fit ran on enough bent rows; ``message`` says why not.
        angle: psi (rad, >= 0): the angle between the sensor axis and the surface normal as
            the fiber's plane sees it (module docstring: an upper bound off that plane).
        sigma: its 1-sigma (rad).
        side: +1 or -1, the side of the fiber's plane the tip slid toward (the lean's sign).
        rows: the rows used.
    """

    success: bool
    message: str
    angle: float = math.nan
    sigma: float = math.inf
    side: float = 0.0
    rows: int = 0


def bow_shortening(c: FloatArray | float, kl: FloatArray, length: FloatArray) -> FloatArray:
    """End shortening (m) of the clamped beam-column's bow, ``1/2 int_0^L y'^2 ds``, with slope
    ``y' = c (cos(k (L - s)) - cos kL) / cos kL``, in closed form (kL in [0, pi/2))."""
    x = np.asarray(kl, dtype=np.float64)
    cos = np.cos(x)
    safe = np.where(x > 1e-4, x, 1.0)
    # int_0^1 (cos(x v) - cos x)^2 dv = 1/2 + cos^2 x - 3 sin(2x) / (4x); x^4 / 45 near 0
    integral = np.where(x > 1e-4, 0.5 + cos**2 - 0.75 * np.sin(2 * x) / safe, x**4 / 45.0)
    return np.asarray(0.5 * length * np.asarray(c) ** 2 * integral / cos**2)


def measure_slip_path(
    strains: FloatArray,
    advances: FloatArray,
    lengths: FloatArray,
    from_tip: FloatArray,
    EA: float,
    EI: float,
    fiber_offset: float,
) -> SlipPath:
    """psi from a slipping contact's loading rows (module docstring).

    Args:
        strains: (N, G) grating-mean strains of the loading rows, in order.
        advances: (N,) the stage's advance at each (m).
        lengths: (N,) the exposed length at each (m).
        from_tip: (G, 2) each grating's (d0, d1) from the sensor tip (m).
        EA, EI, fiber_offset: the sensor's section.
    """
    y = np.asarray(strains, dtype=np.float64)
    u = np.asarray(advances, dtype=np.float64)
    L = np.asarray(lengths, dtype=np.float64)
    if y.ndim != 2 or u.shape != (y.shape[0],) or L.shape != u.shape:
        raise ValueError(f"strains (N, G), advances and lengths (N,), got {y.shape}, {u.shape}")
    bent = np.max(np.abs(y), axis=1) if y.size else np.zeros(0)
    use = np.flatnonzero(np.isfinite(u) & (L > 0) & (bent > MIN_BENDING) & (bent < MAX_BENDING))
    if use.size > MAX_ROWS:
        use = use[np.linspace(0, use.size - 1, MAX_ROWS).round().astype(int)]
    if use.size < MIN_ROWS:
        return SlipPath(False, f"{use.size} bent rows, the path's fit needs {MIN_ROWS}")
    rows = _Rows(y[use], u[use], L[use], from_tip, EA, EI, fiber_offset)
    return rows.fit()


@dataclass(frozen=True)
class _Rows:
    y: FloatArray
    u: FloatArray
    L: FloatArray
    from_tip: FloatArray
    EA: float
    EI: float
    dy: float

    def loads(self, c: float) -> tuple[FloatArray, float]:
        """Each row's load fitting its strains at lean tan ``c`` (candidates, then golden
        section), and the strains' residual sum of squares."""
        cap = LOAD_SHARE * capacity(self.EI, 1.0) / self.L**2
        f = np.linspace(0.0, 1.0, _CANDIDATES) ** 2
        grid = cap[:, None] * f[None, :]
        n, j = grid.shape
        h = lateral_shape(grid.ravel(), np.repeat(self.L, j), self.from_tip, self.EI, self.dy)
        r = self.y[:, None, :] + grid[:, :, None] / self.EA - c * h.reshape(n, j, -1)
        best = np.argmin(np.sum(r * r, axis=-1), axis=1)
        lo = grid[np.arange(n), np.maximum(best - 1, 0)]
        hi = grid[np.arange(n), np.minimum(best + 1, j - 1)]
        lo, hi = golden_brackets(lambda x: self._ss(c, x), lo, hi, _GOLDEN)
        P = 0.5 * (lo + hi)
        return P, float(np.sum(self._ss(c, P)))

    def _ss(self, c: float, P: FloatArray) -> FloatArray:
        shape = lateral_shape(P, self.L, self.from_tip, self.EI, self.dy)
        v = self.y + P[:, None] / self.EA - c * shape
        return np.asarray(np.sum(v * v, axis=1))

    def path(self, c: float) -> tuple[float, float, float, float]:
        """At lean tan ``c``: (strains' rss, advances' rss, tan psi, its least-squares
        variance per unit noise variance)."""
        P, rss_y = self.loads(c)
        k = np.sqrt(P / self.EI)
        kl = k * self.L
        w = abs(c) * (np.tan(kl) - kl) / np.where(k > 0, k, 1.0)  # the slide lifts either way
        own = P * self.L / self.EA + bow_shortening(c, kl, self.L)
        a = np.column_stack([np.ones_like(P), P ** (2.0 / 3.0), w])
        coef, *_ = np.linalg.lstsq(a, self.u - own, rcond=None)
        r = self.u - own - a @ coef
        cov = np.linalg.pinv(a.T @ a)
        return rss_y, float(r @ r), float(coef[2]), float(cov[2, 2])

    def fit(self) -> SlipPath:
        results = np.array([self.path(math.tan(g)) for g in LEAN_GRID])
        n, g = self.y.shape
        s2_y = max(float(results[:, 0].min()) / max(n * (g - 1), 1), 1e-30)
        s2_u = max(float(results[:, 1].min()) / max(n - 3, 1), 1e-30)
        chi2 = results[:, 0] / s2_y + results[:, 1] / s2_u
        best = int(np.argmin(chi2))
        _, _, t, var = results[best]
        if not (math.isfinite(t) and t > 0):
            return SlipPath(False, f"the path's fit gave tan(psi) = {t:.3g}: no slide along a "
                            "surface in the fiber's plane", rows=n)  # fmt: skip
        near = results[chi2 - chi2[best] <= 1.0, 2]
        spread = 0.5 * float(near.max() - near.min())
        sigma_t = math.hypot(math.sqrt(var * s2_u), spread)
        sigma = math.hypot(sigma_t / (1.0 + t * t), MODEL_FLOOR)
        side = 1.0 if LEAN_GRID[best] >= 0 else -1.0
        return SlipPath(True, "", math.atan(t), sigma, side, n)
