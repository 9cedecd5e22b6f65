"""Stiffness of the three-dimensional layer: trilinear boxes, selectively integrated.

Every element of :class:`~sim.fem3d.grid.HexGrid` is an axis-aligned box of edges (h_x, h_y,
h_z) and volume V, so the integral of a product of two basis-function derivatives over it is
``V / (h_a h_b)`` times the same integral over the unit cube. Each element matrix is therefore
a combination of nine constant 24 x 24 matrices, formed for all elements in one product.

The energy density is ``mu |dev eps|^2 + K/2 (tr eps)^2``; the deviatoric part is integrated
exactly (2 x 2 x 2 Gauss points), the volumetric part at the element centre (selective reduced
integration, the classical cure of trilinear elements' volumetric locking; on boxes it equals the
mean-dilatation B-bar method and the Q1-P0 mixed element with its pressure condensed). The
Poisson's ratio is capped at ``NU_CAP`` (K / mu = 1000) so the matrix stays positive definite.

Each element's shear and bulk moduli are the volume averages of the materials it holds (the
matrix, and the part inside each spherical inclusion, sampled at 4^3 points): an inclusion's
boundary need not follow the grid.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray
from scipy import sparse  # type: ignore[import-untyped,unused-ignore]

from .grid import HexGrid
from .problem import Inclusion

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

NU_CAP = 0.4995
"""Largest Poisson's ratio used (K / mu = 1000): 0.5 itself would make the matrix singular."""
_SAMPLES = 4


def _unit_cube_tensors() -> tuple[FloatArray, FloatArray]:
    """The shear part T and bulk part Q, each (9, 24, 24) for the pairs (a, b) of axes, of the
    element matrix of the unit cube with unit moduli (dof ``3 l + alpha``)."""
    g = 0.5 + np.array([-1.0, 1.0]) / (2.0 * np.sqrt(3.0))
    corners = list(itertools.product((0, 1), repeat=3))  # (c, b, a) -> reversed below
    offsets = np.array([(a, b, c) for c, b, a in corners], dtype=float)  # l = a + 2b + 4c

    def grads(p: FloatArray) -> FloatArray:  # (3, 8) dN_l/dxi_a at p
        val = np.where(offsets == 1, p, 1.0 - p)  # (8, 3)
        sign = np.where(offsets == 1, 1.0, -1.0)
        out = np.empty((3, 8))
        for a in range(3):
            others = [b for b in range(3) if b != a]
            out[a] = sign[:, a] * val[:, others[0]] * val[:, others[1]]
        return out

    R = np.zeros((3, 3, 8, 8))  # integral of dN_l/da dN_m/db over the cube
    for p in itertools.product(g, repeat=3):
        d = grads(np.array(p))
        R += np.einsum("al,bm->ablm", d, d) / 8.0
    c = grads(np.full(3, 0.5))
    T = np.zeros((3, 3, 24, 24))
    Q = np.zeros((3, 3, 24, 24))
    for a, b in itertools.product(range(3), repeat=2):
        for alpha, beta in itertools.product(range(3), repeat=2):
            block = np.zeros((8, 8))
            # mu (dN_l/dbeta dN_m/dalpha + delta_ab grad.grad) - 2 mu / 3 dN_l/dalpha dN_m/dbeta
            if (a, b) == (beta, alpha):
                block += R[a, b]
            if alpha == beta and a == b:
                block += R[a, b]
            if (a, b) == (alpha, beta):
                block -= 2.0 / 3.0 * R[a, b]
                Q[a, b, alpha::3, beta::3] = np.outer(c[a], c[b])
            T[a, b, alpha::3, beta::3] = block
    return T.reshape(9, 24, 24), Q.reshape(9, 24, 24)


_T, _Q = _unit_cube_tensors()


def moduli(poisson: float, contrast: float = 1.0) -> tuple[float, float]:
    """(shear, bulk) moduli of a material of Young's modulus ``contrast`` (units of the matrix's
    E) and Poisson's ratio ``poisson`` (capped at :data:`NU_CAP`)."""
    nu = min(poisson, NU_CAP)
    return contrast / (2.0 * (1.0 + nu)), contrast / (3.0 * (1.0 - 2.0 * nu))


def element_moduli(
    grid: HexGrid, poisson: float, inclusions: Sequence[Inclusion]
) -> tuple[FloatArray, FloatArray]:
    """(nel,) shear and bulk moduli of every box: the volume average over what it holds."""
    mu0, k0 = moduli(poisson)
    mu = np.full(grid.n_elements, mu0)
    bulk = np.full(grid.n_elements, k0)
    if not inclusions:
        return mu, bulk
    centres, sizes = grid.centres(), grid.sizes()
    t = (np.arange(_SAMPLES) + 0.5) / _SAMPLES - 0.5
    offsets = np.stack(np.meshgrid(t, t, t, indexing="ij"), axis=-1).reshape(-1, 3)
    for inc in inclusions:
        reach = np.abs(centres - inc.centre) <= inc.radius + sizes
        near = np.flatnonzero(reach.all(axis=1))
        pts = centres[near, None, :] + offsets[None] * sizes[near, None, :]
        inside = (((pts - inc.centre) ** 2).sum(axis=2) <= inc.radius**2).mean(axis=1)
        mu_i, k_i = moduli(inc.poisson, inc.contrast)
        if inc.contrast >= 1.0:  # the softer (Reuss) average: the matrix's way
            mu[near] = 1.0 / (1.0 / mu[near] + inside * (1.0 / mu_i - 1.0 / mu0))
            bulk[near] = 1.0 / (1.0 / bulk[near] + inside * (1.0 / k_i - 1.0 / k0))
        else:  # the stiffer (Voigt) average: again the matrix's way
            mu[near] += inside * (mu_i - mu0)
            bulk[near] += inside * (k_i - k0)
    return mu, bulk


def assemble(grid: HexGrid, mu: FloatArray, bulk: FloatArray) -> sparse.csr_matrix:
    """The global stiffness (3 n_nodes square, dof ``3 node + axis``) for element moduli."""
    h = grid.sizes()
    volume = h.prod(axis=1)
    weight = volume[:, None, None] / (h[:, :, None] * h[:, None, :])  # (nel, 3, 3)
    weight = weight.reshape(-1, 9)
    data = (weight * mu[:, None]) @ _T.reshape(9, -1) + (weight * bulk[:, None]) @ _Q.reshape(9, -1)
    dofs = (3 * grid.elements()[:, :, None] + np.arange(3)).reshape(-1, 24)
    rows = np.broadcast_to(dofs[:, :, None], (dofs.shape[0], 24, 24)).ravel()
    cols = np.broadcast_to(dofs[:, None, :], (dofs.shape[0], 24, 24)).ravel()
    n = 3 * grid.n_nodes
    return sparse.csr_matrix((data.ravel(), (rows, cols)), shape=(n, n))
