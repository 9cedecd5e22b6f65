"""The world of a whole patch (sim.fem3d.patch): one factorisation, a tip anywhere, any number
of inclusions; checked against a direct solve, the axisymmetric reference and itself.

Small layers (h = 2 R, 4-5 R wide) on coarse patches, a few seconds each; docs/maps.md has the
same checks on the map's own mesh.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.sparse import linalg as splinalg

from palpate.sim.fem import load_table
from palpate.sim.fem.solver import solve_indentation
from palpate.sim.fem3d import Inclusion, InclusionProblem
from palpate.sim.fem3d.patch import (
    PatchProblem,
    PatchWorld,
    factor,
    shallow_filled,
    solve_compliance,
    touchable,
)
from palpate.sim.fem3d.solver import ContactError, fixed_dofs
from palpate.sim.fem3d.stiffness import assemble, element_moduli

SMALL = InclusionProblem(
    thickness_ratio=2.0, radius_ratio=5.0, poisson=0.45, depth_max=0.36, n_depths=6
)
BELOW = Inclusion(0.0, 0.0, 1.0, 0.5, 5.0)


def _patch(*inclusions: Inclusion, fine: float = 0.2, half: float = 0.8) -> PatchProblem:
    solid = dataclasses.replace(SMALL, inclusions=inclusions)
    return PatchProblem(solid, (-half, -half, half, half), fine=fine, depth_fine=1.6)


@pytest.fixture(autouse=True, scope="module")
def _own_cache(tmp_path_factory) -> None:
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("PALPATE_CACHE_DIR", str(tmp_path_factory.mktemp("patch")))
        yield


def test_the_condensed_compliance_is_the_direct_solve() -> None:
    problem = _patch(Inclusion(0.3, -0.2, 0.9, 0.4, 4.0), fine=0.25, half=0.4)
    solved = solve_compliance(problem)
    grid = problem.grid()
    mu, bulk = element_moduli(grid, SMALL.poisson, problem.solid.inclusions)
    K = assemble(grid, mu, bulk)
    free = np.ones(3 * grid.n_nodes, dtype=bool)
    free[fixed_dofs(grid, "bonded", "full")] = False
    lu = splinalg.splu(K[free][:, free].tocsc())
    surface = touchable(problem, grid)
    column = {int(d): k for k, d in enumerate(np.flatnonzero(free))}
    for j in (0, surface.size // 2, surface.size - 1):
        load = np.zeros(int(free.sum()))
        load[column[3 * int(surface[j]) + 2]] = 1.0
        u = lu.solve(load)
        direct = np.array([u[column[3 * int(s) + 2]] for s in surface])
        assert np.allclose(solved.matrix[:, j], direct, rtol=1e-8, atol=1e-12 * direct.max())
    assert np.allclose(solved.matrix, solved.matrix.T)
    assert np.all(np.linalg.eigvalsh(solved.matrix) > 0.0)


@pytest.mark.slow
def test_on_the_axis_it_matches_an_axisymmetric_solve_holding_the_sphere() -> None:
    layer = SMALL.layer()
    held = solve_indentation(SMALL.layer(inclusion=(1.0, 0.5, 5.0, 0.45)))
    assert held.success
    effect = held.forces / load_table(layer).forces
    ratios = factor(_patch(BELOW), (0.0, 0.0))
    assert effect[-1] > 1.1  # a visible inclusion
    deep = np.asarray(SMALL.depths()) >= 0.16  # contacts two elements wide and more
    excess = (ratios[deep] - 1.0) / (effect[deep] - 1.0)
    # a sphere 2.5 elements in radius on the patch's grid (the map's 2.5 mm sphere is 3.6):
    # its excess over the layer reads up to 11 % low (its elements' moduli are averages)
    assert np.all(np.abs(excess - 1.0) < 0.12), excess


@pytest.mark.slow
def test_a_sphere_far_away_changes_nothing_and_soft_reads_soft() -> None:
    near = Inclusion(0.0, 0.0, 1.0, 0.5, 5.0)
    far = Inclusion(0.0, 3.6, 1.0, 0.5, 5.0)  # 3.6 R off: beyond what the tip feels
    soft = Inclusion(0.0, 0.0, 1.0, 0.5, 0.3)
    alone = factor(_patch(near, fine=0.25, half=0.5), (0.0, 0.0))
    both = factor(_patch(near, far, fine=0.25, half=0.5), (0.0, 0.0))
    assert np.max(np.abs(both / alone - 1.0)) < 0.003
    assert np.all(alone[1:] > 1.05)
    assert np.all(factor(_patch(soft, fine=0.25, half=0.5), (0.0, 0.0))[1:] < 0.97)


@pytest.mark.slow
def test_the_factor_falls_away_from_the_sphere_and_is_one_without() -> None:
    problem = _patch(BELOW, fine=0.25, half=1.2)
    over = factor(problem, (0.0, 0.0))
    aside = factor(problem, (1.2, 0.0))
    assert np.all(aside < over)
    assert np.all(np.abs(aside - 1.0) < 0.5 * (over - 1.0))
    assert np.array_equal(factor(problem.reference, (0.3, 0.1)), np.ones(len(SMALL.depths())))


def test_shallow_depths_that_touch_no_node_take_the_first_touching_factor() -> None:
    ratio = shallow_filled(np.array([0.0, 0.0, 2.2, 4.4]), np.array([0.0, 0.0, 2.0, 4.0]))
    assert ratio.tolist() == pytest.approx([1.1, 1.1, 1.1, 1.1])
    with pytest.raises(ContactError, match="touches no node"):
        shallow_filled(np.zeros(3), np.zeros(3))


def test_a_world_refuses_a_point_off_its_patch_and_a_patch_past_the_edge() -> None:
    problem = _patch(BELOW)
    with pytest.raises(ValueError, match="outside the world's patch"):
        PatchWorld(SMALL.layer(), problem, (0.9, 0.0))
    with pytest.raises(ValueError, match="reaches the layer's edge"):
        PatchProblem(SMALL, (-3.5, -1.0, 3.5, 1.0))
    with pytest.raises(ValueError, match="x_min, y_min"):
        PatchProblem(SMALL, (1.0, -1.0, -1.0, 1.0))
