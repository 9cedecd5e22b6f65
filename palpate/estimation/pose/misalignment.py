"""The lean of the tissue's load on the sensor, measured from the loading record's strains.

An oblique contact loads the beam across its axis before it buckles when the tip slides: the
tissue's resultant then leans ``gamma`` off the axis and the free tip carries a lateral load
``Q = P tan(gamma)`` beside the axial ``P``. A clamped beam-column with a tip load across it
(linear theory, ``k = sqrt(P / EI)``, ``d`` the distance from the tip) bends as::

    kappa(d) = tan(gamma) k sin(k d) / cos(k L)          (0 <= d <= L; straight inside the tube)

so its gratings read, besides the uniform axial strain -P/EA and the onset mode's bow of an
imperfect pinned beam (``estimation.beam.states.onset_mode``, free amplitude per sample)::

    y_ng = -P_n / EA + A_n m_g + c h_g(P_n),    h_g(P) = -dy mean over grating g of kappa/tan(gamma)

with ``c = s tan(gamma)``: ``s`` the cosine between the lateral load and the fiber's bending
plane (one fiber sees one component, signed: which side the load bends the beam toward).

Two fits of the rows: a *pinned* tip (c = 0, loads up to 1.2 P_cr, the aligned model) and a
*free* tip (c fitted on a grid of leans then refined, loads below ``LOAD_SHARE`` of the free
tip's capacity ``(pi/2)^2 EI / L^2``, an eighth of P_cr); per row the load (candidates, then
golden section) and the bow's amplitude (linear) are fitted. ``Lean.aligned_chi2`` is how much
worse the pinned fit is, in noise variances: the *detection* of a lateral load.

The detection is robust, the *size* of the lean is not: to first order the lateral load bends
the beam by ``c P d / EI``, so the strains give the product cP; P itself comes only from the
axial strain P/EA, at most ~17 ue below the free tip's capacity and ~0.3 % of the lateral
bending's own uniform part at a 7 deg lean, and from the shape's slow change with kL. Measured
on the world's slipping contacts (``docs/orientation.md``, section 7) the fitted size misses
the truth by more than its profile interval: it is reported, never used as a measurement. The
misalignment of a sliding tip is measured from its path instead (``estimation.pose.slip_path``:
strains and stage, no friction needed), and carried in :class:`Lean` beside the detection.

What it measures is the lean of the *load*, not the misalignment psi of the axis to the normal:

- a slipping contact leans by ``gamma = psi - atan(mu)`` (Coulomb): the lean is a lower bound
  of psi, and psi = lean + atan(mu) when the friction mu is known;
- a sticking contact (tan psi <= mu) holds the tip: the load lies along the axis, the lean is 0
  whatever psi below the friction angle (only the pin's small offset bends the beam; see
  ``docs/orientation.md``). A lean of 0 therefore verifies nothing about psi.

Only rows before buckling with bending below ``MAX_BENDING`` are used (beyond it the onset
mode stops describing the pinned beam), thinned to ``MAX_ROWS``. Shapes: N rows, G gratings.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..beam.column import capacity, lateral_shape, lateral_shape_by_grating
from ..beam.states import onset_mode
from .golden import golden_brackets

FloatArray = NDArray[np.float64]

LOAD_SHARE = 0.95  # of the free tip's capacity (pi/2)^2 EI / L^2: rows above are left out
MAX_BENDING = 600e-6  # strain: rows bent more are past the onset mode's small-amplitude shape
MIN_ROWS = 10  # loaded rows the fit needs
MAX_ROWS = 120  # rows beyond are thinned evenly (the fit's cost is linear in them)
MODEL_FLOOR = math.radians(0.3)  # rad added in quadrature: the shapes' own error (see docs)
DETECT_CHI2 = 100.0  # a lateral load when no lean fits worse by this (10 sigma): measured
# 1-6.5 on sticking and aligned records, 2.6e4-4e4 on slipping ones (docs/orientation.md)
LENGTH_STEP = 1e-4  # m: rows are grouped by exposed length to this step for the shapes
_BELOW = 120  # candidate loads per row below LOAD_SHARE of the capacity
_ABOVE = 120  # and above it, up to _ABOVE_MAX capacities (a pinned tip's loads, to 1.2 P_cr)
_ABOVE_MAX = 10.0
_GOLDEN_C, _GOLDEN = 16, 14  # golden-section steps on c, and on each row's load
GRID_DEG = 40.0  # the lean searched over +-this
GRID_POINTS = 21

__all__ = ["Lean", "capacity", "lateral_shape", "measure_lean"]


@dataclass(frozen=True)
class Lean:
    """The lean of the load measured from a record.

    Attributes:
        success: the fit ran on enough loaded rows; ``message`` says why not.
        lean: signed component of the load's lean in the fiber's bending plane (rad), the free
            tip's best fit: its size is not a measurement (module docstring).
        sigma: the profile's 1-sigma half-width (rad) plus ``MODEL_FLOOR`` in quadrature.
        rows: loaded rows the fit used.
        load_share: the largest load of the better fit (free or pinned tip) over the free
            tip's capacity (a pinned tip's record goes past 1; a slipping tip's stays below).
        aligned_chi2: how much worse no lean at all fits, in units of the noise variance.
        misalignment: psi (rad), the axis's angle to the surface normal measured from the
            slipping tip's path (``estimation.pose.slip_path``), nan where not measured (no lateral
            load: a sticking or square contact); misalignment_sigma: its 1-sigma (rad).
    """

    success: bool
    message: str
    lean: float = 0.0
    sigma: float = math.inf
    rows: int = 0
    load_share: float = 0.0
    aligned_chi2: float = 0.0
    misalignment: float = math.nan
    misalignment_sigma: float = math.inf

    @property
    def measured(self) -> bool:
        """The slipping tip's path gave the misalignment."""
        return math.isfinite(self.misalignment) and math.isfinite(self.misalignment_sigma)

    @property
    def lateral(self) -> bool:
        """The strains show a lateral load (the tip slid on an oblique surface): no lean at
        all fits worse by more than ``DETECT_CHI2`` noise variances."""
        return self.success and self.aligned_chi2 > DETECT_CHI2

    def record(self) -> dict[str, object]:
        """The fields as JSON values (a trial log's estimate record; inf sigma as null; the
        misalignment's two only where it was measured, as a log before it has them)."""
        d: dict[str, object] = dataclasses.asdict(self)
        d["sigma"] = self.sigma if math.isfinite(self.sigma) else None
        if not self.measured:
            del d["misalignment"], d["misalignment_sigma"]
        return d

    @classmethod
    def from_record(cls, d: dict[str, object]) -> Lean:
        """From :meth:`record`; ValueError for a record that is not one."""
        try:
            sigma = d["sigma"]
            return cls(
                bool(d["success"]),
                str(d["message"]),
                float(d["lean"]),  # type: ignore[arg-type]
                math.inf if sigma is None else float(sigma),  # type: ignore[arg-type]
                int(d["rows"]),  # type: ignore[call-overload]
                float(d["load_share"]),  # type: ignore[arg-type]
                float(d["aligned_chi2"]),  # type: ignore[arg-type]
                float(d.get("misalignment", math.nan)),  # type: ignore[arg-type]
                float(d.get("misalignment_sigma", math.inf)),  # type: ignore[arg-type]
            )
        except (KeyError, TypeError, ValueError) as exc:
            raise ValueError(f"a lean record needs the fields of Lean: {exc}") from exc

    def as_dict(self) -> dict[str, object]:
        return {
            "success": self.success,
            "message": self.message,
            "lean_deg": math.degrees(self.lean),
            "sigma_deg": math.degrees(self.sigma) if math.isfinite(self.sigma) else None,
            "rows": self.rows,
            "load_share": self.load_share,
            "aligned_chi2": self.aligned_chi2,
            "lateral": self.lateral,
            "misalignment_deg": math.degrees(self.misalignment) if self.measured else None,
            "misalignment_sigma_deg": (
                math.degrees(self.misalignment_sigma) if self.measured else None
            ),
        }


def measure_lean(
    strains: FloatArray,
    lengths: FloatArray,
    from_tip: FloatArray,
    EA: float,
    EI: float,
    fiber_offset: float,
) -> Lean:
    """The load's lean from the pre-buckling rows of a loading record (module docstring).

    Args:
        strains: (N, G) grating-mean strains of the rows before buckling, G >= 3.
        lengths: (N,) exposed length at each row (m).
        from_tip: (G, 2) each grating's (d0, d1) from the sensor tip (m).
        EA, EI: the sensor's axial (N) and flexural (N m^2) rigidity; fiber_offset: dy (m).

    Raises:
        ValueError: shapes or non-positive rigidities.
    """
    y = np.asarray(strains, dtype=np.float64)
    L = np.asarray(lengths, dtype=np.float64)
    if y.ndim != 2 or y.shape[1] < 3 or L.shape != (y.shape[0],):
        raise ValueError(f"strains (N, G >= 3) and lengths (N,), got {y.shape} and {L.shape}")
    if not (EA > 0 and EI > 0 and fiber_offset != 0):
        raise ValueError("EA and EI must be > 0 and fiber_offset != 0")
    keep = np.all(np.isfinite(y), axis=1) & (L > 0)
    y, L = y[keep], L[keep]
    groups = _groups(L)
    modes = {g: onset_mode(_arcs(from_tip, g * LENGTH_STEP), g * LENGTH_STEP, fiber_offset)
             for g in np.unique(groups)}  # fmt: skip
    m = np.array([modes[g] for g in groups]).reshape(y.shape)
    cap = (0.5 * math.pi) ** 2 * EI / L**2
    # a row with every grating still inside the tube has no onset mode (it would normalise to
    # NaN): it carries nothing of the lean and is left out
    bows = np.any(m != 0.0, axis=1)
    use = np.flatnonzero((np.max(np.abs(y), axis=1) < MAX_BENDING) & bows)
    if use.size > MAX_ROWS:
        use = use[np.linspace(0, use.size - 1, MAX_ROWS).round().astype(int)]
    if use.size < MIN_ROWS:
        return Lean(False, f"{use.size} rows before buckling, the fit needs {MIN_ROWS}")
    model = _Model.build(y[use], m[use], L[use], cap[use], from_tip, EA, EI, fiber_offset)
    return _profile(model)


@dataclass(frozen=True)
class _Model:
    """The rows and, per row, the candidate loads P_j = f_j cap_n with their lateral shapes.

    The per-grating arrays are grating-major (G first): the sums over a row's few gratings are
    then G - 1 whole-array additions in order, which is what numpy's sum over a last axis
    shorter than 8 does element by element (the same results, without the reduction's
    per-element overhead on a 3-long axis)."""

    y: FloatArray  # (G, N)
    unit: FloatArray  # (G, N): the onset mode, normalised per row
    cap: FloatArray  # (N,)
    loads: FloatArray  # (N, J) candidate loads
    quadratic: tuple[FloatArray, FloatArray, FloatArray]  # (N, J) each: see build
    L: FloatArray  # (N,)
    from_tip: FloatArray  # (G, 2)
    EA: float
    EI: float
    dy: float

    @classmethod
    def build(
        cls, y: FloatArray, m: FloatArray, L: FloatArray, cap: FloatArray, from_tip: FloatArray,
        EA: float, EI: float, dy: float,
    ) -> _Model:  # fmt: skip
        below = LOAD_SHARE * np.linspace(0.0, 1.0, _BELOW) ** 2  # dense near the capacity
        above = np.linspace(LOAD_SHARE, _ABOVE_MAX, _ABOVE + 1)[1:]
        f = np.concatenate([below, above])
        loads = cap[:, None] * f[None, :]
        clipped = np.minimum(loads, LOAD_SHARE * cap[:, None])  # saturated past the capacity
        n, j = loads.shape
        h = lateral_shape_by_grating(clipped.ravel(), np.repeat(L, j), from_tip, EI, dy)
        unit = (m / np.linalg.norm(m, axis=1, keepdims=True)).T
        base = y.T[:, :, None] + loads[None, :, :] / EA  # (G, N, J): the part without c
        # the candidates' squared residual, quadratic in c: |b - c h|^2 = A - 2 c B + c^2 C
        # with b and h the base and the lateral shape with the onset mode taken out per row
        b = _without_mode(base, unit[:, :, None])
        hp = _without_mode(h.reshape(-1, n, j), unit[:, :, None])
        quadratic = (_in_order(list(b * b)), _in_order(list(b * hp)), _in_order(list(hp * hp)))
        return cls(y.T, unit, cap, loads, quadratic, L, from_tip, EA, EI, dy)

    @property
    def rows(self) -> int:
        return int(self.y.shape[1])

    @property
    def gratings(self) -> int:
        return int(self.y.shape[0])

    def rss(self, c: float, pinned: bool = False) -> tuple[float, FloatArray]:
        """Residual sum of squares at ``c`` with each row's load and bow fitted, and the loads:
        the best candidate load, then golden-section refined between its neighbours. A free
        tip's loads stay below the capacity; ``pinned`` (c = 0) lets them reach 1.2 P_cr."""
        rss, P = self.rss_many(np.array([c]), pinned)
        return float(rss[0]), P[0]

    def rss_many(self, cs: FloatArray, pinned: bool = False) -> tuple[FloatArray, FloatArray]:
        """:meth:`rss` at every ``c`` of ``cs`` (C,) at once (one numpy call for all: the rows are
        few, the calls' overhead was the cost): (C,) sums and (C, N) loads."""
        cols = self.loads.shape[1] if pinned else _BELOW
        loads = self.loads[:, :cols]
        bb, bh, hh = (q[None, :, :cols] for q in self.quadratic)
        c3 = cs[:, None, None]
        j = np.argmin(bb - 2.0 * c3 * bh + c3 * c3 * hh, axis=-1)  # (C, N): the best candidate
        rows = np.arange(j.shape[1])[None, :]
        lo = loads[rows, np.maximum(j - 1, 0)]
        hi = loads[rows, np.minimum(j + 1, cols - 1)]
        lo, hi = golden_brackets(lambda x: self._row_ss(cs, x), lo, hi, _GOLDEN)
        P = 0.5 * (lo + hi)
        return np.sum(self._row_ss(cs, P), axis=-1), P

    def _row_ss(self, cs: FloatArray, P: FloatArray) -> FloatArray:
        """(C, N): each row's residual at its load P (C, N) and the lean c of its line (the
        lateral shape as :func:`lateral_shape_by_grating` computes it, element for element,
        with the rows' grating spans taken once). The gratings are stacked (G, C, N): each
        element sees the arithmetic of a grating at a time, in the same order."""
        k = np.sqrt(np.maximum(np.minimum(P, self._saturation), 0.0) / self.EI)
        half_k = 0.5 * k
        d_sum, d_diff, span = self._spans
        integral = 2.0 * np.sin(half_k * d_sum) * np.sin(half_k * d_diff)
        shape = -self.dy * integral / (span * np.cos(k * self.L))
        axial = P / self.EA
        resid = (self._y3 + axial) - cs[:, None] * shape
        return _in_order(list(_without_mode(resid, self._unit3) ** 2))

    @functools.cached_property
    def _y3(self) -> FloatArray:
        """(G, 1, N): the strains, to broadcast over the leans."""
        return self.y[:, None, :]

    @functools.cached_property
    def _unit3(self) -> FloatArray:
        """(G, 1, N): the unit onset mode, to broadcast over the leans."""
        return self.unit[:, None, :]

    @functools.cached_property
    def _saturation(self) -> FloatArray:
        """(N,): the largest load a free tip's shape is taken at, LOAD_SHARE of the capacity."""
        return np.asarray(LOAD_SHARE * self.cap)

    @functools.cached_property
    def _spans(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """The rows' grating spans on the exposed beam, (G, 1, N) each: d0 + d1 and d1 - d0,
        and the gratings' lengths (G, 1, 1)."""
        d0 = np.minimum(self.from_tip[:, 0, None], self.L)  # (G, N)
        d1 = np.minimum(self.from_tip[:, 1, None], self.L)
        span = (self.from_tip[:, 1] - self.from_tip[:, 0])[:, None, None]
        return (d0 + d1)[:, None, :], (d1 - d0)[:, None, :], span


def _without_mode(v: FloatArray, u: FloatArray) -> FloatArray:
    """v (gratings first) with its component along the unit onset mode u taken out, the
    gratings' products summed in order."""
    along = _in_order(list(v * u))
    out: FloatArray = v - along * u
    return out


def _in_order(terms: list[FloatArray]) -> FloatArray:
    """t0 + t1 + ... added left to right: numpy's sum over a last axis of fewer than 8
    elements, element for element."""
    total = terms[0]
    for term in terms[1:]:
        total = total + term
    return total


def _profile(model: _Model) -> Lean:
    """c = s tan(gamma) of a free tip minimising the residual, on a grid then refined, and its
    sigma from the profile (the half-width where the residual rises by one noise variance);
    beside it how much worse a pinned tip with no lateral load fits."""
    grid = np.tan(np.radians(np.linspace(-GRID_DEG, GRID_DEG, GRID_POINTS)))
    rss = model.rss_many(grid)[0]
    k = int(np.argmin(rss))
    lo, hi = grid[[max(k - 1, 0)]], grid[[min(k + 1, grid.size - 1)]]  # of the minimum: refined
    lo, hi = golden_brackets(lambda x: model.rss_many(x)[0], lo, hi, _GOLDEN_C)
    c = float(0.5 * (lo + hi)[0])
    rss_free, P = model.rss(c)
    rss_pinned, P_pinned = model.rss(0.0, pinned=True)
    rows = model.rows
    dof = max(rows * (model.gratings - 2) - 1, 1)  # each row: its load and its bow
    s2 = max(min(rss_free, rss_pinned) / dof, 1e-30)
    sigma_c = _half_width(grid, (rss - rss_free) / s2)
    sigma = math.hypot(sigma_c / (1.0 + c * c), MODEL_FLOOR)
    share = float(np.max((P if rss_free < rss_pinned else P_pinned) / model.cap))
    chi2 = (rss_pinned - rss_free) / s2
    return Lean(True, "", math.atan(c), sigma, rows, share, chi2)


def _half_width(grid: FloatArray, chi2: FloatArray) -> float:
    """Half the width in c of the region where the profile's chi2 (above its minimum) is <= 1,
    the grid's crossings interpolated linearly; at least half a grid step."""
    inside = np.flatnonzero(chi2 <= 1.0)
    step = float(np.max(np.diff(grid)))
    if inside.size == 0:
        return 0.5 * step
    i, j = int(inside[0]), int(inside[-1])
    left = _crossing(grid, chi2, i - 1, i) if i > 0 else float(grid[0])
    right = _crossing(grid, chi2, j + 1, j) if j + 1 < grid.size else float(grid[-1])
    return max(0.5 * (right - left), 0.5 * step)


def _crossing(grid: FloatArray, chi2: FloatArray, out: int, inside: int) -> float:
    """Where chi2 crosses 1 between grid points ``out`` (> 1) and ``inside`` (<= 1)."""
    x0, x1, y0, y1 = grid[inside], grid[out], chi2[inside], chi2[out]
    return float(x0 + (1.0 - y0) * (x1 - x0) / (y1 - y0))


def _groups(L: FloatArray) -> NDArray[np.int64]:
    return np.asarray(np.round(L / LENGTH_STEP), dtype=np.int64)


def _arcs(from_tip: FloatArray, length: float) -> FloatArray:
    """The gratings' arcs from the clamp, s = L - d (the onset mode treats s < 0 as inside the
    tube: straight)."""
    return np.stack([length - from_tip[:, 1], length - from_tip[:, 0]], axis=1)
