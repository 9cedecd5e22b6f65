"""The finite-element indentation solver against closed forms, under refinement, and failing.

Coarse meshes (resolution 3-4) keep the file fast; the reference-grade numbers are in
docs/tissue-fe.md (``python -m benchmarks.tissue_fe``).
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from palpate.estimation.contact.hertz import hertz_force
from palpate.estimation.contact.layer import dimitriadis_coefficients
from palpate.estimation.contact.sneddon import sneddon_bracket, sneddon_y
from palpate.sim.fem.problem import LayerProblem
from palpate.sim.fem.solver import SolverOptions, solve_indentation

THICK = {"thickness_ratio": 200.0, "radius_ratio": 200.0}


def hertz_ratio(problem: LayerProblem, depths: np.ndarray, forces: np.ndarray) -> np.ndarray:
    """F_FE / F_Hertz (E = R = 1)."""
    return forces / hertz_force(1.0, depths, 1.0, problem.poisson)


@pytest.mark.parametrize("poisson", [0.3, 0.5])
def test_small_depth_on_a_thick_layer_is_hertz(poisson: float) -> None:
    problem = LayerProblem(**THICK, poisson=poisson, depth_max=0.01, n_depths=4, resolution=4)
    res = solve_indentation(problem)
    assert res.success, res.message
    ratio = hertz_ratio(problem, res.depths, res.forces)
    assert np.all(np.abs(ratio - 1.0) < 0.01), ratio
    # Hertz's contact radius sqrt(R delta), to the surface mesh spacing
    assert np.all(np.abs(res.contact_radii / np.sqrt(res.depths) - 1.0) < 0.05)


def test_deep_indentation_of_a_thick_layer_is_sneddon() -> None:
    problem = LayerProblem(**THICK, poisson=0.45, depth_max=0.5, n_depths=5, resolution=4)
    res = solve_indentation(problem)
    assert res.success, res.message
    y = sneddon_y(res.depths)
    sneddon = sneddon_bracket(y, np.tanh(y)) / (1.0 - problem.poisson**2)
    assert np.all(np.abs(res.forces / sneddon - 1.0) < 0.01), res.forces / sneddon
    assert np.all(np.abs(res.contact_radii / np.tanh(y) - 1.0) < 0.05)
    # and Hertz is visibly off there (the sphere is not a paraboloid)
    assert hertz_ratio(problem, res.depths, res.forces)[-1] < 0.97


def first_order_slope(problem: LayerProblem) -> float:
    """The slope at chi = 0 of a cubic fitted to F/F_Hertz - 1 against chi = sqrt(R delta)/h."""
    res = solve_indentation(problem)
    assert res.success, res.message
    chi = np.sqrt(res.depths) / problem.thickness_ratio
    y = hertz_ratio(problem, res.depths, res.forces) - 1.0
    coef = np.linalg.lstsq(np.stack([chi, chi**2, chi**3], axis=1), y, rcond=None)[0]
    return float(coef[0])


@pytest.mark.parametrize("poisson", [0.3, 0.45])
def test_thin_bonded_layer_first_order_term(poisson: float) -> None:
    """chi <= 0.5 (h = R/2): the fitted first-order coefficient is Dimitriadis' -2 a0 / pi."""
    k1 = dimitriadis_coefficients(poisson, bonded=True)[0]
    assert first_order_slope(thin_layer(poisson, "bonded")) == pytest.approx(k1, rel=0.05)


def test_thin_sliding_layer_first_order_term_does_not_depend_on_poisson() -> None:
    """On a frictionless base the exact law does not depend on nu (docs/tissue-fe.md); Dimitriadis'
    non-bonded coefficient does (0.66 at nu = 0, 0.88 at nu = 0.5): the FE lies in between
    and is the same at both ends."""
    slopes = [first_order_slope(thin_layer(nu, "sliding")) for nu in (0.0, 0.5)]
    assert slopes[0] == pytest.approx(slopes[1], rel=0.01)
    low = dimitriadis_coefficients(0.0, bonded=False)[0]
    high = dimitriadis_coefficients(0.5, bonded=False)[0]
    assert low < slopes[0] < high


def thin_layer(poisson: float, base: str) -> LayerProblem:
    return LayerProblem(
        thickness_ratio=0.5,
        radius_ratio=10.0,
        poisson=poisson,
        base=base,
        depth_max=0.0625,
        n_depths=10,
        resolution=4,
    )


def test_force_converges_under_refinement() -> None:
    forces = []
    for resolution in (3, 4, 6):
        problem = LayerProblem(
            thickness_ratio=2.857,
            radius_ratio=11.43,
            n_depths=3,
            depth_max=0.5,
            resolution=resolution,
        )
        res = solve_indentation(problem)
        assert res.success, res.message
        forces.append(res.forces)
    change = [np.max(np.abs(b / a - 1.0)) for a, b in itertools.pairwise(forces)]
    assert change[-1] < 2e-3, change


def test_no_locking_at_incompressibility() -> None:
    """A bonded thin layer at nu = 0.5 (mixed u-p) continues the nu -> 0.5 limit smoothly and
    is far stiffer than Hertz; displacement-only elements would lock here."""
    forces = {}
    for nu in (0.49, 0.499, 0.5):
        problem = LayerProblem(
            thickness_ratio=0.5,
            radius_ratio=10.0,
            poisson=nu,
            depth_max=0.04,
            n_depths=3,
            resolution=3,
        )
        res = solve_indentation(problem)
        assert res.success, res.message
        forces[nu] = res.forces[-1] * (1.0 - nu**2)  # F / E*, finite as nu -> 0.5
    assert forces[0.5] == pytest.approx(forces[0.499], rel=0.01)
    assert forces[0.499] > forces[0.49]


def test_neo_hookean_matches_linear_at_small_depth_and_stiffens_in_a_thin_layer() -> None:
    common = {"thickness_ratio": 1.0, "radius_ratio": 8.0, "n_depths": 4, "resolution": 3}
    lin = solve_indentation(LayerProblem(**common, depth_max=0.36))
    neo = solve_indentation(LayerProblem(**common, depth_max=0.36, material="neo-hookean"))
    assert lin.success, lin.message
    assert neo.success, neo.message
    assert neo.forces[0] == pytest.approx(lin.forces[0], rel=0.02)
    assert neo.forces[-1] > 1.03 * lin.forces[-1]


@pytest.mark.parametrize(("poisson", "low", "high"), [(0.0, 1.03, 1.08), (0.5, 0.999, 1.005)])
def test_full_stick_against_frictionless(poisson: float, low: float, high: float) -> None:
    """Stick stiffens a compressible layer by a few % (the surface would slide inward) and does
    nothing to an incompressible one at small depth (no radial surface motion to stop)."""
    common = {
        "thickness_ratio": 1.0,
        "radius_ratio": 8.0,
        "n_depths": 3,
        "resolution": 3,
        "depth_max": 0.09,
        "poisson": poisson,
    }
    slip = solve_indentation(LayerProblem(**common))
    stick = solve_indentation(LayerProblem(**common, contact="stick"))
    assert slip.success, slip.message
    assert stick.success, stick.message
    ratio = stick.forces / slip.forces
    assert np.all((low < ratio) & (ratio < high)), ratio


def test_non_convergence_is_reported_not_nan() -> None:
    problem = LayerProblem(
        thickness_ratio=1.0, radius_ratio=8.0, material="neo-hookean", n_depths=3, resolution=3
    )
    res = solve_indentation(problem, SolverOptions(max_iterations=2, max_bisections=1))
    assert not res.success
    assert "delta/R" in res.message
    assert "bisections" in res.message
    assert res.depths.size < 3
    assert np.all(np.isfinite(res.forces))
    assert res.forces.shape == res.depths.shape


def test_bad_problem_is_rejected_by_name() -> None:
    with pytest.raises(ValueError, match="material"):
        LayerProblem(thickness_ratio=1.0, radius_ratio=8.0, material="rubber")
    with pytest.raises(ValueError, match="poisson"):
        LayerProblem(thickness_ratio=1.0, radius_ratio=8.0, poisson=0.6)
    assert math.isclose(
        LayerProblem.from_dimensions(3.5e-3, 10e-3, 40e-3).thickness_ratio,
        LayerProblem.from_dimensions(3.5, 10.0, 40.0).thickness_ratio,
    )
