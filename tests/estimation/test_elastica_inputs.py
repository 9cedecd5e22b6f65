"""How the elastica solvers fail: bad input names the argument, non-convergence is reported."""

from __future__ import annotations

import math

import numpy as np
import pytest

from palpate.estimation.beam.elastica import (
    E_OVER_L_MAX,
    ElasticaConvergenceError,
    accurate,
    post_buckling,
    shooting,
)
from palpate.estimation.beam.elastica.closed_form import wavenumber


@pytest.mark.parametrize("method", ["accurate", "fast", "shooting"])
@pytest.mark.parametrize("bad", [-1e-9, math.nan, math.inf, -math.inf, E_OVER_L_MAX * 1.001])
def test_bad_e_over_L_is_a_value_error_naming_it(method: str, bad: float) -> None:
    with pytest.raises(ValueError, match=r"^e_over_L "):
        post_buckling(bad, method=method)
    with pytest.raises(ValueError, match=r"^e_over_L "):
        post_buckling(np.array([1e-3, bad]), method=method)


def test_unknown_method_is_named() -> None:
    with pytest.raises(ValueError, match=r"^method "):
        post_buckling(1e-3, method="magic")


@pytest.mark.parametrize("name", ["s0", "s1"])
@pytest.mark.parametrize("bad", [-0.1, 1.1, math.nan])
def test_bad_interval_is_named(name: str, bad: float) -> None:
    sol = post_buckling(1e-3, method="fast")
    args = {"s0": 0.2, "s1": 0.3}
    args[name] = bad
    with pytest.raises(ValueError, match=rf"^{name} "):
        sol.mean_curvature(**args)


def test_shape_functions_reject_arc_outside_the_beam() -> None:
    sol = post_buckling(1e-3)
    with pytest.raises(ValueError, match=r"^s "):
        sol.theta(1.5)


def test_accurate_reports_non_convergence() -> None:
    with pytest.raises(ElasticaConvergenceError, match=r"accurate: brentq .* e_over_L=0.1"):
        accurate.modulus(0.1, maxiter=2)


def test_wavenumber_beyond_the_branch_is_reported() -> None:
    with pytest.raises(ElasticaConvergenceError, match=r"beyond the first-mode branch"):
        wavenumber(0.99)


def test_shooting_counts_failures_and_solve_raises() -> None:
    opts = shooting.ShootingOptions(maxiter=2)
    result = shooting.shoot(np.array([0.0, 0.1]), opts)
    assert result.failures == 2
    assert not result.success.any()
    assert np.isnan(result.p).all()
    assert "unbuckled" in result.messages[0]
    assert "e_over_L=0.1" in result.messages[1]
    with pytest.raises(ElasticaConvergenceError, match=r"shooting failed on 2 of 2 states"):
        shooting.solve(np.array([0.0, 0.1]), opts)
