"""The tissue's force law from a finite-element table: what the world's contact solver calls.

``F(delta) = E R^2 f(delta / R)`` with the dimensionless table ``f`` of one
:class:`~sim.fem.problem.LayerProblem`, interpolated as a correction to the Hertz growth::

    f(x) = c x^(3/2) exp(g(s)),    s = sqrt(x),    c = 4 / (3 (1 - nu^2)),

with ``g`` the PCHIP (shape-preserving, C1) interpolant of ``log(f / (c x^1.5))`` through the
tabulated depths and the exact limit ``g(0) = 0`` (every table tends to Hertz at vanishing
depth: the contact becomes small against the layer and the strains vanish). The variable s makes
the thin-layer correction, which starts linear in the contact radius ~ sqrt(delta), a smooth
function. Then F and dF/ddelta are continuous, F(0) = dF/ddelta(0) = 0, and F increases (checked
when the table is loaded). Beyond the deepest tabulated depth g is continued linearly in s (value
and slope matched): an extrapolation, still C1 and increasing; :attr:`FeTissueLaw.depth_limit`
says where it starts.

``force_and_stiffness`` and ``inverse`` take arrays (any shape); the ``_at`` twins take floats
and run in pure Python (a few microseconds: the contact solver's per-sample path).
"""

from __future__ import annotations

import bisect
import functools
import math
from dataclasses import dataclass
from typing import Protocol, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .problem import LayerProblem
from .table import ForceTable, load_table, table_key

FloatArray = NDArray[np.float64]
T = TypeVar("T", float, FloatArray)

_RTOL = 1e-13
_MAX_ITER = 60


@dataclass(frozen=True)
class _Curve:
    """g(s) as cubic Hermite data: knots s (n,), values g (n,), slopes dg/ds (n,)."""

    s: FloatArray
    g: FloatArray
    m: FloatArray
    c: float  # Hertz constant of f
    s_list: list[float]
    g_list: list[float]
    m_list: list[float]


class TableSource(Protocol):
    """A force table that is not one axisymmetric layer's (``sim.fem3d.InclusionWorld``)."""

    @property
    def key(self) -> str: ...

    def table(self) -> ForceTable: ...

    def __hash__(self) -> int: ...


Problem = LayerProblem | TableSource
"""What a :class:`FeTissueLaw` reads its table from."""


def _load(problem: Problem) -> ForceTable:
    return load_table(problem) if isinstance(problem, LayerProblem) else problem.table()


@functools.lru_cache(maxsize=64)
def _curve(problem: Problem) -> _Curve:
    return curve_from_table(_load(problem))


def curve_from_table(table: ForceTable) -> _Curve:
    """The interpolation data of ``table``.

    Raises:
        ValueError: the table's forces are not positive or the law would not increase.
    """
    nu = table.problem.poisson
    c = 4.0 / (3.0 * (1.0 - nu * nu))
    x, f = table.depths, table.forces
    if not (np.all(f > 0) and np.all(np.diff(x) > 0) and x[0] > 0):
        raise ValueError(f"table {table.key}: forces must be > 0 at increasing depths > 0")
    s = np.concatenate([[0.0], np.sqrt(x)])
    g = np.concatenate([[0.0], np.log(f / (c * x**1.5))])
    m = pchip_slopes(s, g)
    if np.any(3.0 + s * m <= 0.0):  # d log f / d log s = 3 + s g'(s) at the knots
        raise ValueError(f"table {table.key}: the interpolated force would not increase")
    return _Curve(s, g, m, c, s.tolist(), g.tolist(), m.tolist())


def pchip_slopes(x: FloatArray, y: FloatArray) -> FloatArray:
    """Knot slopes of the shape-preserving PCHIP interpolant (Fritsch-Carlson with the
    weighted harmonic mean and the one-sided three-point end rule: scipy's
    ``PchipInterpolator``, whose import costs ~0.4 s in a fresh process against ~1 ms for the
    table read). ``x`` (n,) increasing, ``y`` (n,), n >= 3."""
    h = np.diff(x)
    m = np.diff(y) / h
    d = np.zeros_like(y)
    a, b = m[:-1], m[1:]
    flat = (np.sign(a) != np.sign(b)) | (a == 0) | (b == 0)
    w1, w2 = 2 * h[1:] + h[:-1], h[1:] + 2 * h[:-1]
    safe_a, safe_b = np.where(flat, 1.0, a), np.where(flat, 1.0, b)
    d[1:-1] = np.where(flat, 0.0, (w1 + w2) / (w1 / safe_a + w2 / safe_b))
    d[0] = _pchip_end(h[0], h[1], m[0], m[1])
    d[-1] = _pchip_end(h[-1], h[-2], m[-1], m[-2])
    return d


def _pchip_end(h0: float, h1: float, m0: float, m1: float) -> float:
    d = ((2 * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
    if np.sign(d) != np.sign(m0):
        return 0.0
    if np.sign(m0) != np.sign(m1) and abs(d) > 3 * abs(m0):
        return float(3 * m0)
    return float(d)


def _cubic(t: T, h: T, y0: T, y1: T, m0: T, m1: T) -> tuple[T, T]:
    """Cubic Hermite value and derivative at t in [0, 1] of an interval of width h with end
    values y0, y1 and end slopes m0, m1 (plain arithmetic: floats or arrays)."""
    a0, a1 = m0 * h, m1 * h
    t2 = t * t
    t3 = t2 * t
    g = (
        (2 * t3 - 3 * t2 + 1) * y0
        + (t3 - 2 * t2 + t) * a0
        + (3 * t2 - 2 * t3) * y1
        + (t3 - t2) * a1
    )
    dg = ((6 * t2 - 6 * t) * (y0 - y1) + (3 * t2 - 4 * t + 1) * a0 + (3 * t2 - 2 * t) * a1) / h
    return g, dg


def _hermite(cv: _Curve, s: FloatArray) -> tuple[FloatArray, FloatArray]:
    """g(s) and g'(s) (vectorised), linear beyond the last knot."""
    i = np.clip(np.searchsorted(cv.s, s, side="right") - 1, 0, cv.s.size - 2)
    h = cv.s[i + 1] - cv.s[i]
    t = np.minimum((s - cv.s[i]) / h, 1.0)
    g, dg = _cubic(t, h, cv.g[i], cv.g[i + 1], cv.m[i], cv.m[i + 1])
    beyond = s > cv.s[-1]
    g = np.where(beyond, cv.g[-1] + cv.m[-1] * (s - cv.s[-1]), g)
    return g, np.where(beyond, cv.m[-1], dg)


def _hermite_at(cv: _Curve, s: float) -> tuple[float, float]:
    """Scalar twin of :func:`_hermite`."""
    ks = cv.s_list
    if s >= ks[-1]:
        return cv.g_list[-1] + cv.m_list[-1] * (s - ks[-1]), cv.m_list[-1]
    i = max(0, bisect.bisect_right(ks, s) - 1)
    h = ks[i + 1] - ks[i]
    gs, ms = cv.g_list, cv.m_list
    return _cubic((s - ks[i]) / h, h, gs[i], gs[i + 1], ms[i], ms[i + 1])


@dataclass(frozen=True)
class FeTissueLaw:
    """A tissue sample whose force law is a finite-element table (hashable: it is a key).

    Attributes:
        problem: the dimensionless problem (geometry / R, Poisson's ratio, material, base,
            friction, mesh), or another source of a table (a layer with inclusions:
            ``sim.fem3d.InclusionWorld``); its table is loaded by key on first use.
        modulus: Young's modulus E in Pa (small-strain modulus for neo-Hookean).
        tip_radius: radius R of the spherical tip in m.
    """

    problem: Problem
    modulus: float
    tip_radius: float

    def __post_init__(self) -> None:
        if not (math.isfinite(self.modulus) and self.modulus > 0):
            raise ValueError(f"modulus must be a positive finite value in Pa, got {self.modulus}")
        if not (math.isfinite(self.tip_radius) and self.tip_radius > 0):
            raise ValueError(
                f"tip_radius must be a positive finite value in m, got {self.tip_radius}"
            )

    @property
    def key(self) -> str:
        """The key of the table this law reads."""
        return (
            table_key(self.problem) if isinstance(self.problem, LayerProblem) else self.problem.key
        )

    @property
    def depth_limit(self) -> float:
        """Deepest tabulated depth (m); beyond it the law is extrapolated."""
        return float(self.tip_radius * _load(self.problem).depths[-1])

    @property
    def _scale(self) -> float:
        return self.modulus * self.tip_radius**2

    def force(self, delta: ArrayLike) -> FloatArray:
        """Contact force F (N) at depth ``delta`` (m, >= 0); same shape as delta."""
        return self.force_and_stiffness(delta)[0]

    def force_and_stiffness(self, delta: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """(F in N, dF/ddelta in N/m) at depths ``delta`` (m, >= 0); same shape as delta."""
        d = np.asarray(delta, dtype=np.float64)
        if not np.all(np.isfinite(d)) or np.any(d < 0):
            raise ValueError("indentation depth delta must be finite and >= 0")
        cv = _curve(self.problem)
        x = d / self.tip_radius
        s = np.sqrt(x)
        g, dg = _hermite(cv, s)
        f = cv.c * x * s * np.exp(g)
        # df/dx = f (1.5 / x + g'(s) / (2 s)) = c e^g (1.5 s + x g'(s) / 2): finite at 0.
        dfdx = cv.c * np.exp(g) * (1.5 * s + 0.5 * x * dg)
        return self._scale * f, self.modulus * self.tip_radius * dfdx

    def force_and_stiffness_at(self, delta: float) -> tuple[float, float]:
        """(F, dF/ddelta) at one depth, in plain floats."""
        if not delta > 0:
            if delta == 0:
                return 0.0, 0.0
            raise ValueError("indentation depth delta must be finite and >= 0")
        if not math.isfinite(delta):
            raise ValueError("indentation depth delta must be finite and >= 0")
        cv = _curve(self.problem)
        x = delta / self.tip_radius
        s = math.sqrt(x)
        g, dg = _hermite_at(cv, s)
        e = cv.c * math.exp(g)
        return self._scale * e * x * s, self.modulus * self.tip_radius * e * (
            1.5 * s + 0.5 * x * dg
        )

    def inverse(self, force: ArrayLike) -> FloatArray:
        """Depth (m) at which the tissue pushes back with ``force`` (N, >= 0); same shape.

        Newton on ``3 t + g(e^t) = log(f / c)`` in ``t = log s`` (its slope 3 + s g'(s) > 0),
        from the Hertz root, steps bounded and kept inside the bracket; 2-5 steps reach 1e-13.
        """
        f = np.asarray(force, dtype=np.float64)
        if not np.all(np.isfinite(f)) or np.any(f < 0):
            raise ValueError("force must be finite and >= 0")
        cv = _curve(self.problem)
        positive = f > 0
        target = np.log(np.where(positive, f, 1.0) / (self._scale * cv.c))
        t = target / 3.0
        lo = np.full_like(t, -np.inf)
        hi = np.full_like(t, np.inf)
        for _ in range(_MAX_ITER):
            s = np.exp(t)
            g, dg = _hermite(cv, s)
            r = 3.0 * t + g - target
            lo = np.where(r < 0, t, lo)
            hi = np.where(r >= 0, t, hi)
            new = t - np.clip(r / (3.0 + s * dg), -2.0, 2.0)
            bracketed = np.isfinite(lo) & np.isfinite(hi)
            new = np.where(((new < lo) | (new > hi)) & bracketed, 0.5 * (lo + hi), new)
            done = np.abs(new - t) <= _RTOL
            t = new
            if np.all(done | ~positive):
                break
        return np.where(positive, self.tip_radius * np.exp(2.0 * t), 0.0)

    def inverse_at(self, force: float) -> float:
        """Depth for one force, in plain floats (same method as :meth:`inverse`)."""
        if not (force >= 0 and math.isfinite(force)):
            raise ValueError("force must be finite and >= 0")
        if force == 0:
            return 0.0
        cv = _curve(self.problem)
        target = math.log(force / (self._scale * cv.c))
        t = target / 3.0
        lo, hi = -math.inf, math.inf
        for _ in range(_MAX_ITER):
            s = math.exp(t)
            g, dg = _hermite_at(cv, s)
            r = 3.0 * t + g - target
            if r < 0:
                lo = t
            else:
                hi = t
            new = t - max(-2.0, min(2.0, r / (3.0 + s * dg)))
            if (new < lo or new > hi) and math.isfinite(lo) and math.isfinite(hi):
                new = 0.5 * (lo + hi)
            done = abs(new - t) <= _RTOL
            t = new
            if done:
                break
        return self.tip_radius * math.exp(2.0 * t)
