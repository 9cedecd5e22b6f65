"""The sensor beam in SI units: load, lateral reaction and grating strains against end shortening.

The beam is the clamped-pinned column of paper Eqs. (7)-(12) plus axial stretch. Its total end
shortening e splits into the elastic shortening P L / EA and the geometric shortening e_g of the
inextensible elastica:

    e = P L / EA                        while P < P_cr (straight, pre-buckling), and
    e = P L / EA + e_g,  P = p(e_g / L) EI / L**2   after buckling (first mode, ``fast``).

Both pieces give P = P_cr at e_cr = P_cr L / EA, so ``force`` is continuous at onset. Because
EI / (EA L**2) is tiny (7e-6 for the paper's sensor at 42 mm), e is strictly increasing in e_g and
``force(e)`` is single valued over the whole supported branch; its inverse is not: P rises from
P_cr to P_peak = 23.01 EI/L**2 (rising branch, e_g/L <= 0.4536) and falls to 0 at
e_g/L = 0.8121 (falling branch). ``shortening`` returns the branch you ask for.

Arc positions of gratings are metres from the clamp (the tube tip), s = L - distance from the
sensor tip. Arc at s < 0 is inside the tube and straight; arc beyond the pin (s > L) is rejected.
Signs: the beam bows toward -y with positive curvature in its main lobe (from about 0.3 L to the
pin, where the paper's gratings are), so bending strains there have the sign of ``fiber_offset``;
``estimation.fits.strain_fit.fit_strains`` also tries the mirror image and reports which one fitted.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .elastica import fast
from .elastica.constants import E_OVER_L_MAX, E_OVER_L_PEAK, P_CRIT, P_PEAK
from .elastica.errors import ElasticaConvergenceError
from .section import Section

FloatArray = NDArray[np.float64]
Branch = Literal["rising", "falling"]

NEWTON_TOL = 1e-15  # on e_g / L
NEWTON_MAXITER = 30


def _checked(
    name: str, value: ArrayLike, *, lower: float = 0.0, upper: float = math.inf
) -> FloatArray:
    arr = np.asarray(value, dtype=float)
    bad = ~np.isfinite(arr) | (arr < lower) | (arr > upper)
    if np.any(bad):
        first = float(arr[bad].flat[0]) if arr.ndim else float(arr)
        raise ValueError(f"{name} must be finite and in [{lower!r}, {upper!r}], got {first!r}")
    return arr


@dataclass(frozen=True)
class Beam:
    """A sensor beam: rigidities EI (N m**2) and EA (N), fiber offset dy_fbg (m), length L (m)."""

    EI: float
    EA: float
    fiber_offset: float
    length: float

    def __post_init__(self) -> None:
        for name in ("EI", "EA", "length"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
        if not math.isfinite(self.fiber_offset):
            raise ValueError(f"fiber_offset must be finite, got {self.fiber_offset!r}")
        # e must increase with e_g: 1 + lambda dp/de_g > 0 on the whole branch. It fails only for
        # stubby beams (L below about 10 radii of gyration), where the elastica does not apply.
        steepest = float(np.min(fast.load_slope(np.linspace(0.0, E_OVER_L_MAX, 257))))
        if 1.0 + self.slenderness_ratio * steepest <= 0.5:
            raise ValueError(
                f"length {self.length!r} m is too short for this section: EI/(EA L^2) = "
                f"{self.slenderness_ratio:.3g} (needs < {0.5 / -steepest:.3g}); not a slender beam"
            )

    @classmethod
    def from_section(cls, section: Section, length: float) -> Beam:
        return cls(EI=section.EI, EA=section.EA, fiber_offset=section.fiber_offset, length=length)

    # --- scalars -------------------------------------------------------------------------------
    @property
    def slenderness_ratio(self) -> float:
        """lambda = EI / (EA L**2), the elastic shortening per unit load factor."""
        return self.EI / (self.EA * self.length**2)

    @property
    def load_unit(self) -> float:
        """EI / L**2 (N): converts dimensionless p, r to newtons."""
        return self.EI / self.length**2

    def critical_load(self) -> float:
        """P_cr = 20.19 EI / L**2 (N)."""
        return P_CRIT * self.load_unit

    def critical_shortening(self) -> float:
        """End shortening at which the beam buckles, P_cr L / EA (m)."""
        return P_CRIT * self.slenderness_ratio * self.length

    def peak_load(self) -> float:
        """Largest first-mode load, 23.01 EI / L**2 (N), the end of the rising branch."""
        return P_PEAK * self.load_unit

    def max_shortening(self) -> float:
        """Largest supported e (m): the first-mode branch ends where P falls to 0."""
        return E_OVER_L_MAX * self.length

    # --- state from e --------------------------------------------------------------------------
    def geometric_shortening(self, e: ArrayLike) -> FloatArray:
        """e_g / L (elastica part, dimensionless) for total shortening ``e`` (m), any shape.

        Newton on e/L = e_g/L + lambda p(e_g/L), started at e/L - lambda P_CRIT; each step
        contracts by about lambda |dp/de_g| (< 1e-3 for the paper's sensor), so 3-4 steps.
        """
        eps = _checked("e", e, upper=self.max_shortening()) / self.length
        lam = self.slenderness_ratio
        g = np.clip(eps - lam * P_CRIT, 0.0, E_OVER_L_MAX)
        buckled = eps > lam * P_CRIT
        if not np.any(buckled):
            return np.zeros_like(eps)
        for _ in range(NEWTON_MAXITER):
            h = g + lam * fast.load(g) - eps
            step = h / (1.0 + lam * fast.load_slope(g))
            g = np.clip(g - step, 0.0, E_OVER_L_MAX)
            if np.all(np.abs(step[buckled]) <= NEWTON_TOL * (1.0 + g[buckled])):
                return np.where(buckled, g, 0.0)
        raise ElasticaConvergenceError(
            f"Beam.geometric_shortening: Newton did not converge in {NEWTON_MAXITER} steps"
        )

    def force(self, e: ArrayLike) -> FloatArray:
        """Axial load P (N) at total end shortening ``e`` (m, in [0, max_shortening]), any shape."""
        eps = _checked("e", e, upper=self.max_shortening()) / self.length
        g = self.geometric_shortening(eps * self.length)
        return np.asarray(np.where(g > 0.0, fast.load(g) * self.load_unit, self.EA * eps))

    def lateral_force(self, e: ArrayLike) -> FloatArray:
        """Lateral pin reaction R (N) in paper Eq. (7)'s sign (<= 0 in our buckling direction)."""
        return np.asarray(fast.reaction(self.geometric_shortening(e)) * self.load_unit)

    def grating_strains(
        self, e: ArrayLike, intervals: ArrayLike, *, include_axial: bool = False
    ) -> FloatArray:
        """Mean fiber strain over each interval, paper Eq. (12) with Eq. (3): shape e.shape + (G,).

        ``intervals``: (G, 2) arc positions (s0, s1), s0 < s1 <= L, metres from the clamp; arc at
        s < 0 is inside the tube (straight). Bending strain is dy_fbg times the mean of dtheta/ds,
        0 before buckling; ``include_axial`` adds the uniform -P/EA the fiber also carries.
        """
        bending = self.bending_strains(self.geometric_shortening(e), intervals)
        if not include_axial:
            return bending
        return np.asarray(bending - (self.force(e) / self.EA)[..., None])

    def bending_strains(self, g: ArrayLike, intervals: ArrayLike) -> FloatArray:
        """Mean bending strain over each interval for the elastica at geometric (inextensible)
        shortening ratio ``g`` = e_g/L: shape g.shape + (G,). ``grating_strains`` is this at
        ``geometric_shortening(e)``; a caller that knows the shape's e_g (say from the pin
        reaction of an imperfect beam) asks for it directly."""
        s0, s1 = self.intervals(intervals)
        g_arr = np.clip(np.asarray(g, dtype=float), 0.0, E_OVER_L_MAX)[..., None]
        return self.mean_bending(g_arr, s0, s1)

    def intervals(self, intervals: ArrayLike) -> tuple[FloatArray, FloatArray]:
        arr = np.asarray(intervals, dtype=float)
        if arr.ndim != 2 or arr.shape[1] != 2 or arr.shape[0] == 0:
            raise ValueError(f"intervals must have shape (G, 2), got {arr.shape}")
        if not np.all(np.isfinite(arr)):
            raise ValueError("intervals must be finite")
        s0, s1 = arr[:, 0], arr[:, 1]
        if np.any(s1 <= s0):
            raise ValueError("intervals: each grating needs s0 < s1")
        if np.any(s1 > self.length * (1.0 + 1e-12)):
            raise ValueError(
                f"intervals: arc beyond the pin (s > L = {self.length!r} m), "
                f"got {float(s1.max())!r}"
            )
        return s0 / self.length, s1 / self.length

    def mean_bending(self, g: FloatArray, s0: FloatArray, s1: FloatArray) -> FloatArray:
        """``bending_strains`` on arcs already checked: ``s0``, ``s1`` (G,) fractions of L
        (negative inside the tube), ``g`` e_g/L in [0, E_OVER_L_MAX] with a trailing axis of 1
        (shape g.shape + (1,) broadcasts against the gratings). The fit calls it per candidate
        z without re-checking the arcs."""
        a, b = np.clip(s0, 0.0, 1.0), np.clip(s1, 0.0, 1.0)
        sol = fast.solve(g)
        inside = b > a
        mean = sol.mean_curvature(a, np.where(inside, b, a))  # over the exposed part
        mean_total = np.where(inside, mean * (b - a) / (s1 - s0), 0.0)
        return np.asarray(self.fiber_offset * mean_total / self.length)

    # --- inverses ------------------------------------------------------------------------------
    def shortening(self, P: ArrayLike, branch: Branch = "rising") -> FloatArray:
        """Total end shortening e (m) at load ``P`` (N), the inverse of ``force`` on one branch.

        ``"rising"`` (default): the straight beam for P <= P_cr, then the buckled states up to the
        load peak; the branch a loading stage follows first. ``"falling"``: the buckled states
        past the peak, where P decreases to 0 at the end of the branch. P above peak_load()
        has no solution and raises ValueError.
        """
        p = _checked("P", P, upper=self.peak_load() * (1.0 + 1e-12)) / self.load_unit
        p = np.minimum(p, P_PEAK)
        lam = self.slenderness_ratio
        if branch == "rising":
            g = self._invert_load(p, 0.0, E_OVER_L_PEAK)
            straight = p <= P_CRIT
            e_over_L = np.where(straight, lam * p, g + lam * p)
        elif branch == "falling":
            e_over_L = self._invert_load(p, E_OVER_L_PEAK, E_OVER_L_MAX) + lam * p
        else:
            raise ValueError(f"branch must be 'rising' or 'falling', got {branch!r}")
        return np.asarray(e_over_L * self.length)

    @staticmethod
    def _invert_load(p: FloatArray, lo: float, hi: float, iterations: int = 64) -> FloatArray:
        """e_g/L in [lo, hi] with p(e_g/L) = p, p monotonic there: bisection then Newton polish.

        Bisection is needed near the peak, where dp/de_g -> 0 defeats Newton; two Newton steps
        after it restore full precision elsewhere. Targets outside the range clamp to its ends.
        """
        a = np.full(p.shape, lo)
        b = np.full(p.shape, hi)
        increasing = fast.load(np.array(hi)) > fast.load(np.array(lo))
        for _ in range(iterations):
            mid = 0.5 * (a + b)
            below = (fast.load(mid) < p) == increasing
            a, b = np.where(below, mid, a), np.where(below, b, mid)
        g = 0.5 * (a + b)
        for _ in range(2):
            slope = fast.load_slope(g)
            safe = np.abs(slope) > 1e-3
            step = np.where(safe, (fast.load(g) - p) / np.where(safe, slope, 1.0), 0.0)
            g = np.clip(g - step, lo, hi)
        return np.asarray(g, dtype=float)
