"""Taylor-Hood (P2 displacement, P1 pressure) discretisation of the axisymmetric layer.

scikit-fem provides the elements, the quadrature, the reference-to-element maps and the degree
of freedom numbering. The element matrices are contracted here in one ``einsum`` per block over
all elements at once: the 5-component gradient of every local basis function (``B``, shape
(12, 5, nel, nqp)) is computed once per mesh (total Lagrangian: the reference configuration does
not change), so an assembly costs one material evaluation and three contractions. Measured on
2,400 triangles: 0.06 s against 0.6 s for the same matrix through ``skfem.BilinearForm``, which
calls the form once per pair of local basis functions.

Volume elements carry the axisymmetric weight 2 pi r, so forces come out as totals (units E R^2).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray
from scipy import sparse  # type: ignore[import-untyped,unused-ignore]
from skfem import Basis, ElementTriP1, ElementTriP2, ElementVector

from .material import MaterialLaw, Response
from .mesh import LayerMesh

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

_QUADRATURE_ORDER = 4


@dataclass(frozen=True)
class Discretization:
    """Bases, basis gradients and dof maps of one mesh.

    Attributes:
        layer: the mesh and its extent.
        ubasis: vector P2 basis of the displacement (u_r, u_z).
        pbasis: scalar P1 basis of the pressure.
        B: (12, 5, nel, nqp) axisymmetric gradients of the displacement basis functions.
        P: (3, nel, nqp) values of the pressure basis functions.
        weights: (nel, nqp) quadrature weights times 2 pi r.
    """

    layer: LayerMesh
    ubasis: Basis
    pbasis: Basis
    B: FloatArray
    P: FloatArray
    weights: FloatArray

    @property
    def n_u(self) -> int:
        return int(self.ubasis.N)

    @property
    def n_p(self) -> int:
        return int(self.pbasis.N)


class Assembled(NamedTuple):
    """Residuals and tangent blocks of the mixed energy at one state."""

    r_u: FloatArray
    r_p: FloatArray
    K_uu: sparse.csr_matrix
    K_up: sparse.csr_matrix
    K_pp: sparse.csr_matrix


def discretize(layer: LayerMesh) -> Discretization:
    """Bases and the precomputed basis gradients for ``layer``."""
    mesh = layer.mesh
    ubasis = Basis(mesh, ElementVector(ElementTriP2()), intorder=_QUADRATURE_ORDER)
    pbasis = Basis(mesh, ElementTriP1(), intorder=_QUADRATURE_ORDER)
    r = np.asarray(ubasis.global_coordinates())[0]
    nel, nqp = r.shape
    B = np.empty((ubasis.Nbfun, 5, nel, nqp))
    for i, (phi,) in enumerate(ubasis.basis):
        g = phi.grad
        B[i] = [g[0, 0], g[0, 1], g[1, 0], g[1, 1], np.asarray(phi)[0] / r]
    P = np.stack([np.asarray(phi) for (phi,) in pbasis.basis])
    weights = 2.0 * np.pi * r * ubasis.dx
    return Discretization(layer, ubasis, pbasis, B, P, weights)


def gradients(disc: Discretization, u: FloatArray) -> FloatArray:
    """H (5, nel, nqp) of the displacement ``u`` (n_u,) at the quadrature points."""
    H: FloatArray = np.einsum("ie,iaeq->aeq", u[disc.ubasis.element_dofs], disc.B, optimize=True)
    return H


def pressures(disc: Discretization, p: FloatArray) -> FloatArray:
    """p (nel, nqp) of the pressure ``p`` (n_p,) at the quadrature points."""
    pq: FloatArray = np.einsum("ie,ieq->eq", p[disc.pbasis.element_dofs], disc.P, optimize=True)
    return pq


def assemble(
    disc: Discretization,
    law: MaterialLaw,
    shear: float | FloatArray,
    bulk_compliance: float | FloatArray,
    u: FloatArray,
    p: FloatArray,
) -> Assembled:
    """Residuals dPi/du (n_u,), dPi/dp (n_p,) and the tangent blocks at (u, p).

    ``shear`` is mu in units of E, ``bulk_compliance`` 1/K in units of 1/E (0 when
    incompressible): constants, or (nel, nqp) values at the quadrature points (an inclusion;
    the energies are linear in mu). Raises FloatingPointError when the material rejects the
    state (an inverted element).
    """
    H = gradients(disc, u)
    pq = pressures(disc, p)
    resp: Response = _response(law, H, shear)
    weights = disc.weights
    B, P = disc.B, disc.P
    stress = resp.stress + pq * resp.volume_grad
    r_u = np.einsum("iaeq,aeq,eq->ei", B, stress, weights, optimize=True)
    r_p = np.einsum("ieq,eq->ei", P, (resp.volume - bulk_compliance * pq) * weights, optimize=True)
    D = resp.tangent + pq * resp.volume_hess
    k_uu = np.einsum("iaeq,abeq,jbeq,eq->eij", B, D, B, weights, optimize=True)
    k_up = np.einsum("iaeq,aeq,jeq,eq->eij", B, resp.volume_grad, P, weights, optimize=True)
    if isinstance(bulk_compliance, np.ndarray):
        k_pp = -np.einsum("ieq,jeq,eq->eij", P, P, bulk_compliance * weights, optimize=True)
    else:
        k_pp = -bulk_compliance * np.einsum("ieq,jeq,eq->eij", P, P, weights, optimize=True)
    ud, pd = disc.ubasis.element_dofs, disc.pbasis.element_dofs
    return Assembled(
        r_u=_vector(r_u, ud, disc.n_u),
        r_p=_vector(r_p, pd, disc.n_p),
        K_uu=_matrix(k_uu, ud, ud, (disc.n_u, disc.n_u)),
        K_up=_matrix(k_up, ud, pd, (disc.n_u, disc.n_p)),
        K_pp=_matrix(k_pp, pd, pd, (disc.n_p, disc.n_p)),
    )


def _response(law: MaterialLaw, H: FloatArray, shear: float | FloatArray) -> Response:
    """The law's response for a constant shear modulus, or scaled point by point."""
    if not isinstance(shear, np.ndarray):
        return law(H, shear)
    unit = law(H, 1.0)
    return unit._replace(stress=unit.stress * shear, tangent=unit.tangent * shear)


def _vector(local: FloatArray, dofs: IntArray, n: int) -> FloatArray:
    return np.bincount(dofs.T.ravel(), weights=local.ravel(), minlength=n).astype(np.float64)


def _matrix(
    local: FloatArray, rows: IntArray, cols: IntArray, shape: tuple[int, int]
) -> sparse.csr_matrix:
    r = np.broadcast_to(rows.T[:, :, None], local.shape).ravel()
    c = np.broadcast_to(cols.T[:, None, :], local.shape).ravel()
    return sparse.csr_matrix((local.ravel(), (r, c)), shape=shape)
