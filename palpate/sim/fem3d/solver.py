"""The three-dimensional layer's surface compliance, and a sphere's frictionless contact on it.

The layer is linear, so the vertical displacement of the surface nodes the tip can touch
(within R of the indented point: a sphere's contact radius stays below R) under vertical nodal
forces f is ``w = C f``, with ``C`` the inverse stiffness restricted to those nodes' vertical
dofs. One sparse factorisation of the stiffness gives C column by column; only the columns of
nodes that ever touch are computed (a batch of back-substitutions when the contact grows).

Contact at depth delta (Sneddon's kinematics, as the linear axisymmetric world: the gap is
vertical at the undeformed position): ``g = h - delta + C f >= 0``, ``f >= 0``, ``f g = 0``,
with ``h = 1 - sqrt(1 - r^2)`` the sphere's height over the node at distance r. A symmetric
positive definite linear complementarity problem, solved exactly by an active set: release the
nodes whose force turned tensile, else add the nodes that penetrate, until nothing changes. The
force is ``sum f`` (units E R^2). A set that does not settle is reported (:class:`ContactError`),
never a NaN.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy import linalg  # type: ignore[import-untyped,unused-ignore]
from scipy.sparse import linalg as splinalg  # type: ignore[import-untyped,unused-ignore]

from .grid import Feature, HexGrid, graded_axis, nested_dissection
from .problem import InclusionProblem
from .stiffness import assemble, element_moduli

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]

GROWTH = 0.3
"""Spacing growth per unit distance away from a feature (a geometric grading of ratio 1.3)."""
COARSE = 2.0
"""Largest element edge (units of R)."""
PATCH = 1.0
"""Half-width of the finely meshed patch about the indented point (units of R)."""
PER_RADIUS = 8
"""Elements per inclusion radius along each axis, at least."""
_MAX_SWEEPS = 200


class ContactError(RuntimeError):
    """The active set did not settle, or the factorisation failed."""


MULTIPLICITY = {"quarter": 4, "half": 2, "full": 1}
"""Copies of the solved part that make the whole layer (the force is that times the part's)."""


def build_grid(problem: InclusionProblem) -> HexGrid:
    """The graded grid of ``problem``'s solved part (see :mod:`sim.fem3d.grid`): x >= 0 and
    y >= 0 for a quarter, y >= 0 for a half (:meth:`InclusionProblem.canonical`)."""
    symmetry, inclusions = problem.canonical()
    fine = problem.fine
    lateral = [Feature(-PATCH, PATCH, fine)]
    axes: list[list[Feature]] = [list(lateral), list(lateral), [Feature(-PATCH, 0.0, fine)]]
    for inc in inclusions:
        size = max(fine, inc.radius / PER_RADIUS)
        for axis, c in enumerate(inc.centre):
            axes[axis].append(Feature(c - inc.radius, c + inc.radius, size))
    w, h = problem.radius_ratio, problem.thickness_ratio
    x_lo = 0.0 if symmetry == "quarter" else -w
    y_lo = -w if symmetry == "full" else 0.0
    return HexGrid(
        x=graded_axis(x_lo, w, axes[0], GROWTH, COARSE),
        y=graded_axis(y_lo, w, axes[1], GROWTH, COARSE),
        z=graded_axis(-h, 0.0, axes[2], GROWTH, COARSE),
    )


@dataclass
class Compliance:
    """The factorised layer and the surface compliance over the touchable nodes.

    Attributes:
        grid: the mesh of the solved part.
        multiplicity: copies of the part in the layer (:data:`MULTIPLICITY`).
        r: (n,) distance of each touchable surface node from the indented point.
        height: (n,) the sphere's height above each of them, 1 - sqrt(1 - r^2).
        rows: (n,) their vertical dofs in the reduced (free) system.
        columns: computed columns of C, by node index (each (n,)).
    """

    grid: HexGrid
    multiplicity: int
    r: FloatArray
    height: FloatArray
    rows: IntArray
    lu: splinalg.SuperLU
    n_free: int
    columns: dict[int, FloatArray] = field(default_factory=dict)

    def matrix(self, nodes: IntArray) -> FloatArray:
        """(n, len(nodes)) columns of C for ``nodes``, solving the ones not yet known."""
        missing = [int(j) for j in nodes if int(j) not in self.columns]
        if missing:
            rhs = np.zeros((self.n_free, len(missing)))
            rhs[self.rows[missing], np.arange(len(missing))] = 1.0
            sol = self.lu.solve(rhs)
            for k, j in enumerate(missing):
                self.columns[j] = sol[self.rows, k]
        return np.stack([self.columns[int(j)] for j in nodes], axis=1)


def factorise(problem: InclusionProblem, homogeneous: bool = False) -> Compliance:
    """Mesh, assemble and factorise ``problem``'s layer (the expensive step).

    Raises:
        ContactError: the factorisation failed (a singular stiffness).
    """
    symmetry, inclusions = problem.canonical()
    grid = build_grid(problem)
    mu, bulk = element_moduli(grid, problem.poisson, () if homogeneous else inclusions)
    K = assemble(grid, mu, bulk)
    nx, ny, nz = grid.shape
    n = grid.n_nodes
    free = elimination_order(grid, problem.base, symmetry)
    lu = factor_in_order(K[free][:, free].tocsc(), "the 3-D layer")
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    r = np.hypot(grid.x[i], grid.y[j]).ravel()
    inside = r < 1.0
    nodes = grid.node(i.ravel()[inside], j.ravel()[inside], np.full(int(inside.sum()), nz - 1))
    index = np.full(3 * n, -1)
    index[free] = np.arange(free.size)
    r = r[inside]
    return Compliance(
        grid,
        MULTIPLICITY[symmetry],
        r,
        1.0 - np.sqrt(1.0 - r**2),
        index[3 * nodes + 2],
        lu,
        int(free.size),
    )


def elimination_order(
    grid: HexGrid, base: str, symmetry: str, last: IntArray | None = None
) -> IntArray:
    """The free dofs in elimination order (geometric nested dissection of the nodes, a node's
    three dofs together), the dofs ``last`` moved to the end in their own order."""
    is_free = np.ones(3 * grid.n_nodes, dtype=bool)
    is_free[fixed_dofs(grid, base, symmetry)] = False
    order = (3 * nested_dissection(grid.shape)[:, None] + np.arange(3)).ravel()
    if last is None:
        return np.asarray(order[is_free[order]])
    keep = is_free[order] & ~np.isin(order, last)
    return np.concatenate([order[keep], last])


def factor_in_order(K: Any, what: str) -> splinalg.SuperLU:
    """``K`` (CSC, symmetric positive definite, its unknowns in :func:`elimination_order`)
    factorised as ordered: no column reordering, no pivoting.

    Raises:
        ContactError: the factorisation failed (``what`` names the matrix).
    """
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            return splinalg.splu(
                K,
                permc_spec="NATURAL",
                diag_pivot_thresh=0.0,
                options={"SymmetricMode": True},
            )
        except (RuntimeError, RuntimeWarning) as exc:
            raise ContactError(f"factorisation of {what} failed: {exc}") from exc


def fixed_dofs(grid: HexGrid, base: str, symmetry: str) -> IntArray:
    """The fixed dofs: the base's (all of them when bonded; the vertical ones when sliding,
    with pins that hold the rigid in-plane motions no mirror plane holds: no reaction, the
    loads are vertical) and the normal ones on the mirror planes."""
    nx = grid.shape[0]
    i, j, k = (a.ravel() for a in np.meshgrid(*map(np.arange, grid.shape), indexing="ij"))
    node = grid.node(i, j, k)
    parts = [3 * node[k == 0] + 2]
    if base == "bonded":
        parts += [3 * node[k == 0], 3 * node[k == 0] + 1]
    if symmetry == "quarter":
        parts += [3 * node[i == 0], 3 * node[j == 0] + 1]
    elif symmetry == "half":
        parts.append(3 * node[j == 0] + 1)
        if base == "sliding":
            parts.append(3 * grid.node(np.array([0]), np.array([0]), np.array([0])))
    elif base == "sliding":
        corner = grid.node(np.array([0]), np.array([0]), np.array([0]))[0]
        other = grid.node(np.array([nx - 1]), np.array([0]), np.array([0]))[0]
        parts.append(np.array([3 * corner, 3 * corner + 1, 3 * other + 1]))
    return np.unique(np.concatenate(parts))


def contact(
    model: Compliance, delta: float, start: BoolArray | None = None
) -> tuple[float, BoolArray]:
    """Force (units E R^2) at depth ``delta`` (units R) and the touching nodes; ``start``: a
    guess of the touching set (the previous depth's).

    Raises:
        ContactError: the active set did not settle.
    """
    h = model.height
    active = (h < delta) if start is None else (start | (h < delta))
    tol = 1e-12 * max(delta, 1e-12)
    for _ in range(_MAX_SWEEPS):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            return 0.0, active
        C = model.matrix(idx)
        f = linalg.solve(C[idx], delta - h[idx], assume_a="pos")
        if np.any(f < 0.0):
            active[idx[f < 0.0]] = False
            continue
        gap = h - delta + C @ f
        enter = (gap < -tol) & ~active
        if not np.any(enter):
            return float(model.multiplicity * f.sum()), active
        active |= enter
    raise ContactError(f"the contact's active set did not settle at delta/R = {delta:.4g}")


def forces(
    problem: InclusionProblem, homogeneous: bool = False
) -> tuple[FloatArray, FloatArray, Compliance]:
    """The tabulated depths (k,) and forces (k,) of ``problem`` (``homogeneous``: of its
    reference on the same grid), and its compliance."""
    model = factorise(problem, homogeneous)
    depths = np.asarray(problem.depths())
    out = np.empty_like(depths)
    active: BoolArray | None = None
    for k, d in enumerate(depths):
        out[k], active = contact(model, float(d), active)
        active = active.copy()
    return depths, out, model
