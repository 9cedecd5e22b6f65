"""Contact of the layer's top surface with the rigid sphere (units of R; centre (0, 1 - delta)).

Node-to-surface constraints on the P2 surface nodes (in 2D the consistent nodal loads of a
quadratic edge are all positive, 1/6, 2/3, 1/6, so nodal contact is sound), enforced exactly
with Lagrange multipliers and a primal-dual active set:

- ``small`` kinematics (linear material, Sneddon's setting): the gap is vertical at the
  undeformed radius X, ``g = (1 - delta - sqrt(1 - X^2)) - u_z``; nodes at X >= 1 never touch.
- ``finite`` kinematics (neo-Hookean): the gap is the distance of the current position
  ``x = (X + u_r, u_z)`` to the sphere, ``g = |x - c| - 1``, with its curvature in the tangent.

A frictionless node carries one multiplier lambda >= 0 (the force on the layer is lambda dg/du).
A stuck node (full stick) is tied to a material point of the sphere: its position relative to
the centre is frozen at the value it had when it stuck, two multipliers; it is released only if
its normal reaction turns tensile.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import sparse  # type: ignore[import-untyped,unused-ignore]

from .assembly import Discretization

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]


@dataclass(frozen=True)
class Surface:
    """The top surface's nodes, sorted by undeformed radius X (n,), and their dofs (n,)."""

    X: FloatArray
    dof_r: IntArray
    dof_z: IntArray


@dataclass
class ContactState:
    """Which surface nodes touch the sphere, and how.

    Attributes:
        active: (n,) frictionless nodes in contact.
        stuck: (n,) nodes stuck to the sphere (never also ``active``).
        offset: (n, 2) position of each stuck node relative to the sphere's centre.
    """

    active: BoolArray
    stuck: BoolArray
    offset: FloatArray

    @classmethod
    def empty(cls, n: int) -> ContactState:
        return cls(np.zeros(n, bool), np.zeros(n, bool), np.zeros((n, 2)))

    def copy(self) -> ContactState:
        return ContactState(self.active.copy(), self.stuck.copy(), self.offset.copy())

    @property
    def touching(self) -> BoolArray:
        return self.active | self.stuck


@dataclass(frozen=True)
class Constraints:
    """Linearised constraints ``g + C du = 0`` of one Newton step.

    Attributes:
        C: (m, n_u) constraint gradients.
        g: (m,) constraint values.
        geometric: (n_u, n_u) sum of lambda d2g/du2 over the frictionless rows (finite kinematics).
        normal_nodes: indices of the frictionless rows' nodes (first rows of C, in order).
        stuck_nodes: indices of the stuck nodes (then two rows each: r, z).
    """

    C: sparse.csr_matrix
    g: FloatArray
    geometric: sparse.csr_matrix
    normal_nodes: IntArray
    stuck_nodes: IntArray


def top_surface(disc: Discretization) -> Surface:
    """The displacement dofs of the nodes on z = 0, sorted by radius."""
    dofs = disc.ubasis.get_dofs(lambda x: np.abs(x[1]) < 1e-12)
    dof_r = np.concatenate([dofs.nodal["u^1"], dofs.facet["u^1"]])
    dof_z = np.concatenate([dofs.nodal["u^2"], dofs.facet["u^2"]])
    X = disc.ubasis.doflocs[0, dof_r]
    order = np.argsort(X)
    return Surface(X[order], dof_r[order], dof_z[order])


def positions(surface: Surface, u: FloatArray, finite: bool) -> FloatArray:
    """(n, 2) node positions: current (finite) or (X + u_r, u_z) read at X (small)."""
    return np.stack([surface.X + u[surface.dof_r], u[surface.dof_z]], axis=1)


def gaps(
    surface: Surface, u: FloatArray, delta: float, finite: bool
) -> tuple[FloatArray, FloatArray]:
    """Gap (n,) of every surface node and its gradient (n, 2) with respect to (u_r, u_z)."""
    y = positions(surface, u, finite)
    if finite:
        d = y - np.array([0.0, 1.0 - delta])
        rho = np.hypot(d[:, 0], d[:, 1])
        return rho - 1.0, d / rho[:, None]
    X = surface.X
    below = X < 1.0
    profile = 1.0 - delta - np.sqrt(np.where(below, 1.0 - X**2, 0.0))
    g = np.where(below, profile - y[:, 1], np.inf)
    grad = np.broadcast_to(np.array([0.0, -1.0]), y.shape).copy()
    return g, grad


def constraints(
    surface: Surface,
    state: ContactState,
    u: FloatArray,
    delta: float,
    finite: bool,
    normal_force: FloatArray,
    n_u: int,
) -> Constraints:
    """The constraint rows for the current contact state (``normal_force`` (n,): the last
    multipliers of the frictionless nodes, for the curvature term)."""
    g, grad = gaps(surface, u, delta, finite)
    nn = np.flatnonzero(state.active)
    sn = np.flatnonzero(state.stuck)
    rows_n = np.repeat(np.arange(nn.size), 2)
    cols_n = np.stack([surface.dof_r[nn], surface.dof_z[nn]], axis=1).ravel()
    vals_n = grad[nn].ravel()
    rows_s = nn.size + np.arange(2 * sn.size)
    cols_s = np.stack([surface.dof_r[sn], surface.dof_z[sn]], axis=1).ravel()
    C = sparse.csr_matrix(
        (
            np.concatenate([vals_n, np.ones(2 * sn.size)]),
            (np.concatenate([rows_n, rows_s]), np.concatenate([cols_n, cols_s])),
        ),
        shape=(nn.size + 2 * sn.size, n_u),
    )
    y = positions(surface, u, finite)
    centre = np.array([0.0, 1.0 - delta])
    g_stuck = (y[sn] - centre - state.offset[sn]).ravel()
    geometric = (
        _curvature(surface, nn, u, delta, normal_force[nn], n_u)
        if finite
        else sparse.csr_matrix((n_u, n_u))
    )
    return Constraints(C, np.concatenate([g[nn], g_stuck]), geometric, nn, sn)


def _curvature(
    surface: Surface, nodes: IntArray, u: FloatArray, delta: float, lam: FloatArray, n_u: int
) -> sparse.csr_matrix:
    """sum_i lambda_i d2g_i/du2 = lambda (I - n n^T) / rho for the distance gap."""
    y = positions(surface, u, True)[nodes] - np.array([0.0, 1.0 - delta])
    rho = np.hypot(y[:, 0], y[:, 1])
    n = y / rho[:, None]
    block = (np.eye(2)[None] - n[:, :, None] * n[:, None, :]) * (lam / rho)[:, None, None]
    dofs = np.stack([surface.dof_r[nodes], surface.dof_z[nodes]], axis=1)
    rows = np.broadcast_to(dofs[:, :, None], block.shape).ravel()
    cols = np.broadcast_to(dofs[:, None, :], block.shape).ravel()
    return sparse.csr_matrix((block.ravel(), (rows, cols)), shape=(n_u, n_u))


def update(
    state: ContactState,
    cons: Constraints,
    lam: FloatArray,
    gap: FloatArray,
    normal: FloatArray,
    tolerance: float,
) -> tuple[ContactState, bool]:
    """The next active set from multipliers ``lam`` (m,) and the new gaps (n,) with their
    normals (n, 2) (pointing away from the sphere); True if it changed."""
    new = state.copy()
    nn, sn = cons.normal_nodes, cons.stuck_nodes
    new.active[nn[lam[: nn.size] < 0.0]] = False
    stick_force = lam[nn.size :].reshape(-1, 2)
    tensile = (stick_force * normal[sn]).sum(axis=1) < 0.0
    new.stuck[sn[tensile]] = False
    new.active |= (gap < -tolerance) & ~new.stuck
    changed = bool(np.any(new.active != state.active) or np.any(new.stuck != state.stuck))
    return new, changed


def stick_all(
    state: ContactState, surface: Surface, u: FloatArray, delta: float, finite: bool
) -> ContactState:
    """Every frictionless contact node becomes stuck where it is now (full stick)."""
    new = state.copy()
    y = positions(surface, u, finite)
    fresh = new.active
    new.offset[fresh] = y[fresh] - np.array([0.0, 1.0 - delta])
    new.stuck |= fresh
    new.active = np.zeros_like(fresh)
    return new


def contact_radius(
    surface: Surface, u: FloatArray, gap: FloatArray, touching: BoolArray, finite: bool
) -> float:
    """Radius of the contact's edge, between the outermost touching node and the next one.

    Outside a smooth frictionless contact the gap grows like (x - a)^(3/2); two free nodes fix
    ``a``. Clipped to the interval between the last touching and the first free node; 0 when
    nothing touches.
    """
    x = positions(surface, u, finite)[:, 0] if finite else surface.X
    idx = np.flatnonzero(touching)
    if idx.size == 0:
        return 0.0
    last = idx.max()
    if last + 2 >= x.size:
        return float(x[last])
    x0, x1, x2 = x[last], x[last + 1], x[last + 2]
    g1, g2 = gap[last + 1], gap[last + 2]
    if not (math.isfinite(g2) and g2 > g1 > 0.0):
        return float(0.5 * (x0 + x1))
    q = (g2 / g1) ** (2.0 / 3.0)
    a = (x2 - q * x1) / (1.0 - q)
    return float(min(max(a, x0), x1))
