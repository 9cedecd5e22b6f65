"""A patch of the layer with every inclusion in it, a tip anywhere on it: one factorisation.

A map presses at many points of one sample. Rather than a 3-D solve per point, the layer is
meshed once over the whole patch the tip can touch (``fine`` elements over the patch widened
by one tip radius, down to ``depth_fine``; graded beyond), its stiffness factorised once with
the vertical dofs of the touchable surface nodes ordered last. The factor's trailing block is
then the stiffness condensed onto those dofs (the Schur complement ``S = L_tt U_tt`` of a
block LU), and its inverse the dense surface compliance ``C`` of the whole patch: every probe
is a small contact problem on the rows and columns of the nodes within one tip radius of its
point (:func:`sim.fem3d.solver.contact`), milliseconds, for any number of inclusions, stiff or
soft, wherever they lie.

The grid does not follow the inclusions (each element's moduli are the volume averages of what
it holds, :func:`sim.fem3d.stiffness.element_moduli`), so the homogeneous reference, solved on
the same grid, is one for every geometry drawn in the same layer and patch: the inclusions'
factor ``F / F_ref`` at each depth cancels the grid's discretisation error to first order, as
:mod:`sim.fem3d.table` does, and the world multiplies the axisymmetric layer table by it
(:class:`PatchWorld`). Both compliances are kept in the user cache (``cached_arrays``).

Usage::

    problem = PatchProblem(solid, patch=(-2.9, -2.9, 2.9, 2.9))   # units of R
    world = PatchWorld(layer, problem, at=(0.4, -0.3))
    law = FeTissueLaw(world, modulus=E, tip_radius=R)              # sim.fem.law
"""

from __future__ import annotations

import functools
import hashlib
import sys
import time
from dataclasses import asdict, dataclass, replace

import numpy as np
from numpy.typing import NDArray
from scipy import linalg  # type: ignore[import-untyped,unused-ignore]

from ...store.cache import cache_dir, cached_arrays, parameter_record
from ..fem.problem import LayerProblem, significant
from ..fem.table import ForceTable, load_table, table_key
from .grid import Feature, HexGrid, graded_axis
from .problem import InclusionProblem
from .solver import (
    COARSE,
    GROWTH,
    ContactError,
    contact,
    elimination_order,
    factor_in_order,
)
from .stiffness import assemble, element_moduli
from .world import scaled_table

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]

PATCH_VERSION = 1
"""Version of the numbers this module produces; part of every cache record."""
FINE = 0.2
"""Element size over the touchable patch (units of R): a 20 x 20 mm patch of the paper's tip
factorises in about a minute and reads an inclusion's factor within 3 % of its excess over the
axisymmetric reference's (0.25: 27 s, 7 %; docs/maps.md)."""
DEPTH_FINE = 2.0
"""Depth (units of R) the fine elements reach: where inclusions a probe can feel lie."""


@dataclass(frozen=True)
class PatchProblem:
    """A layer with inclusions (its :class:`InclusionProblem`, in the sample's frame) and the
    patch of its surface where the tip's centre may press.

    Attributes:
        solid: the layer and its inclusions (x, y from the sample's origin; units of R).
        patch: ``(x_min, y_min, x_max, y_max)`` of the tip's centre (units of R).
        fine: element size over the patch widened by one tip radius (units of R).
        depth_fine: depth the fine elements reach (units of R).
    """

    solid: InclusionProblem
    patch: tuple[float, float, float, float]
    fine: float = FINE
    depth_fine: float = DEPTH_FINE

    def __post_init__(self) -> None:
        x0, y0, x1, y1 = self.patch
        if not (x0 < x1 and y0 < y1):
            raise ValueError(f"patch must be (x_min, y_min, x_max, y_max), got {self.patch}")
        reach = max(abs(x0), abs(x1), abs(y0), abs(y1)) + 1.0
        if reach >= self.solid.radius_ratio - 1.0:
            raise ValueError(
                f"the patch widened by a tip radius ({reach:g} R) reaches the layer's edge "
                f"({self.solid.radius_ratio:g} R)"
            )
        if not 0.05 <= self.fine <= 0.5:
            raise ValueError(f"fine must be in [0.05, 0.5], got {self.fine}")
        if not 0 < self.depth_fine <= self.solid.thickness_ratio:
            raise ValueError(f"depth_fine must be in (0, thickness], got {self.depth_fine}")

    @property
    def reference(self) -> PatchProblem:
        """The same layer and patch without inclusions (one grid for every geometry)."""
        return replace(self, solid=replace(self.solid, inclusions=()))

    def record(self) -> str:
        """The canonical text of everything that changes this problem's compliance."""
        return parameter_record(PATCH_VERSION, asdict(self))

    def grid(self) -> HexGrid:
        """The tensor grid: ``fine`` over the touchable patch to ``depth_fine``, graded beyond
        (independent of the inclusions)."""
        x0, y0, x1, y1 = self.patch
        w, h = self.solid.radius_ratio, self.solid.thickness_ratio
        return HexGrid(
            x=graded_axis(-w, w, [Feature(x0 - 1.0, x1 + 1.0, self.fine)], GROWTH, COARSE),
            y=graded_axis(-w, w, [Feature(y0 - 1.0, y1 + 1.0, self.fine)], GROWTH, COARSE),
            z=graded_axis(-h, 0.0, [Feature(-self.depth_fine, 0.0, self.fine)], GROWTH, COARSE),
        )


@dataclass(frozen=True, eq=False)
class PatchCompliance:
    """The surface compliance of a patch: vertical displacement of every touchable surface node
    under a unit vertical force at every other (units of R / (E R^2)).

    Attributes:
        xy: (m, 2) the touchable surface nodes' positions (units of R).
        matrix: (m, m) the compliance, symmetric.
        build_seconds: the factorisation's and the inverse's wall time.
    """

    xy: FloatArray
    matrix: FloatArray
    build_seconds: float

    def forces(self, at: tuple[float, float], depths: FloatArray) -> FloatArray:
        """The force (units E R^2) at each depth (units R) of a rigid unit sphere pressing at
        ``at``; frictionless, Sneddon's kinematics as :func:`sim.fem3d.solver.contact`.

        Raises:
            ContactError: a contact's active set did not settle.
        """
        r = np.hypot(self.xy[:, 0] - at[0], self.xy[:, 1] - at[1])
        near = np.flatnonzero(r < 1.0)
        local = _Local(1.0 - np.sqrt(1.0 - r[near] ** 2), self.matrix[np.ix_(near, near)])
        out = np.empty(len(depths))
        active: BoolArray | None = None
        for k, d in enumerate(depths):
            out[k], active = contact(local, float(d), active)  # type: ignore[arg-type]
            active = active.copy()
        return out


@dataclass(frozen=True)
class _Local:
    """The contact's view of the nodes near one probe (what :func:`contact` reads)."""

    height: FloatArray
    full: FloatArray
    multiplicity: int = 1

    def matrix(self, idx: IntArray) -> FloatArray:
        return self.full[:, idx]


def touchable(problem: PatchProblem, grid: HexGrid) -> IntArray:
    """The surface nodes within the patch widened by one tip radius (node numbers)."""
    x0, y0, x1, y1 = problem.patch
    i = np.flatnonzero((grid.x >= x0 - 1.0 - 1e-9) & (grid.x <= x1 + 1.0 + 1e-9))
    j = np.flatnonzero((grid.y >= y0 - 1.0 - 1e-9) & (grid.y <= y1 + 1.0 + 1e-9))
    ii, jj = np.meshgrid(i, j, indexing="ij")
    k = np.full(ii.size, grid.shape[2] - 1)
    return grid.node(ii.ravel(), jj.ravel(), k)


def solve_compliance(problem: PatchProblem) -> PatchCompliance:
    """Mesh, assemble and factorise ``problem``'s layer with the touchable vertical dofs last;
    invert the condensed stiffness (the expensive step: about a minute for 160,000 unknowns).

    Raises:
        ContactError: the factorisation failed (a singular stiffness).
    """
    start = time.perf_counter()
    grid = problem.grid()
    mu, bulk = element_moduli(grid, problem.solid.poisson, problem.solid.inclusions)
    K = assemble(grid, mu, bulk)
    surface = touchable(problem, grid)
    last = 3 * surface + 2
    free = elimination_order(grid, problem.solid.base, "full", last)
    lu = factor_in_order(K[free][:, free].tocsc(), "the patch")
    n, m = free.size, last.size
    if not (np.array_equal(lu.perm_r, np.arange(n)) and np.array_equal(lu.perm_c, np.arange(n))):
        raise ContactError("the patch's factorisation reordered its unknowns")
    lower = lu.L[n - m :, n - m :].toarray()
    upper = lu.U[n - m :, n - m :].toarray()
    eye = np.eye(m)
    inverse = linalg.solve_triangular(
        upper, linalg.solve_triangular(lower, eye, lower=True, unit_diagonal=True)
    )
    matrix = 0.5 * (inverse + inverse.T)
    ix, iy, _ = np.unravel_index(surface, grid.shape, order="F")
    xy = np.stack([grid.x[ix], grid.y[iy]], axis=1)
    return PatchCompliance(xy, matrix, time.perf_counter() - start)


@functools.lru_cache(maxsize=4)
def load_compliance(problem: PatchProblem) -> PatchCompliance:
    """``problem``'s compliance: from the user cache, else solved (a line on stderr) and kept
    there for the next process; kept in memory for this one."""

    def build() -> dict[str, FloatArray]:
        print(
            f"palpate: factorising a 3-D patch ({len(problem.solid.inclusions)} inclusion(s), "
            f"h/R = {problem.solid.thickness_ratio:g}); once, then cached in {cache_dir()}",
            file=sys.stderr,
            flush=True,
        )
        solved = solve_compliance(problem)
        return {
            "xy": solved.xy,
            "matrix": solved.matrix,
            "build_seconds": np.array(solved.build_seconds),
        }

    arrays = cached_arrays("patch", problem.record(), build)
    return PatchCompliance(arrays["xy"], arrays["matrix"], float(arrays["build_seconds"]))


def factor(problem: PatchProblem, at: tuple[float, float]) -> FloatArray:
    """The inclusions' factor on the force at each tabulated depth, the tip pressing at ``at``
    (units of R): ``F / F_ref`` on one grid."""
    depths = np.asarray(problem.solid.depths())
    if not problem.solid.inclusions:
        return np.ones_like(depths)
    with_them = load_compliance(problem).forces(at, depths)
    without = load_compliance(problem.reference).forces(at, depths)
    return shallow_filled(with_them, without)


def shallow_filled(forces: FloatArray, reference: FloatArray) -> FloatArray:
    """``forces / reference``, where the shallowest depths touch no node of the grid (a
    contact narrower than an element: no force either way) taking the first touching depth's
    factor; a reference that never touches is a ContactError."""
    touching = np.flatnonzero(reference > 0.0)
    if touching.size == 0:
        raise ContactError("the tip touches no node of the patch at any tabulated depth")
    ratio = np.empty_like(reference)
    first = int(touching[0])
    ratio[first:] = forces[first:] / reference[first:]
    ratio[:first] = ratio[first]
    return ratio


@dataclass(frozen=True)
class PatchWorld:
    """A layer, its inclusions over a patch, and the tip pressing at ``at`` (units of R).

    Attributes:
        layer: the homogeneous layer as the world has it (material, base, contact).
        problem: the patch and its inclusions.
        at: the point of the surface the tip presses (units of R, the sample's frame).
    """

    layer: LayerProblem
    problem: PatchProblem
    at: tuple[float, float]

    def __post_init__(self) -> None:
        if self.layer.depths() != self.problem.solid.depths():
            raise ValueError("the layer's and the patch's depths differ")
        x0, y0, x1, y1 = self.problem.patch
        x, y = self.at
        if not (x0 - 1e-9 <= x <= x1 + 1e-9 and y0 - 1e-9 <= y <= y1 + 1e-9):
            raise ValueError(
                f"the tip presses at ({x:g}, {y:g}) R, outside the world's patch "
                f"{self.problem.patch}"
            )

    @property
    def key(self) -> str:
        at = f"{significant(self.at[0])},{significant(self.at[1])}"
        both = f"{table_key(self.layer)}|{self.problem.record()}|{at}"
        return hashlib.sha256(both.encode()).hexdigest()[:16]

    def table(self) -> ForceTable:
        """The layer's forces times the inclusions' factor at :attr:`at`."""
        layer = load_table(self.layer)
        n = layer.depths.size
        return scaled_table(layer, factor(self.problem, self.at)[:n], self.key)
