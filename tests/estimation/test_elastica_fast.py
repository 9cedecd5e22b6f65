"""The fast surrogate against the accurate solver, and the paper's shooting baseline."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from palpate.estimation.beam.elastica import E_OVER_L_MAX, post_buckling, shooting
from palpate.estimation.beam.elastica.fast import surrogate

GRID = np.unique(
    np.concatenate(
        [[0.0], np.logspace(-8, np.log10(E_OVER_L_MAX), 300), np.linspace(0, E_OVER_L_MAX, 300)]
    )
)


def _rel(a: np.ndarray, b: np.ndarray, floor: float = 0.0) -> float:
    return float(np.max(np.abs(a - b) / np.maximum(np.abs(b), floor)))


@pytest.mark.slow
def test_fast_matches_accurate_on_a_dense_grid() -> None:
    e = GRID[:, None]
    fast, ref = post_buckling(e, "fast"), post_buckling(e, "accurate")
    assert _rel(fast.p, ref.p, floor=1.0) < 1e-9  # p crosses 0 at the branch end
    nz = GRID > 0
    assert _rel(fast.r[nz], ref.r[nz]) < 1e-9
    assert _rel(fast.tip_angle[nz], ref.tip_angle[nz]) < 1e-9
    # Paper gratings: 3 mm long, centred 10, 18, 26 mm from the tip of a 42 mm beam.
    centres = 1 - np.array([10.0, 18.0, 26.0]) / 42
    s0, s1 = centres - 1.5 / 42, centres + 1.5 / 42
    assert _rel(fast.mean_curvature(s0, s1)[nz], ref.mean_curvature(s0, s1)[nz]) < 1e-9


@given(
    e=st.floats(1e-8, E_OVER_L_MAX),
    s0=st.floats(0.0, 1.0),
    s1=st.floats(0.0, 1.0),
)
def test_fast_mean_curvature_for_any_interval(e: float, s0: float, s1: float) -> None:
    """Error relative to the largest curvature on the beam (a mean can vanish at an inflection)."""
    fast, ref = post_buckling(e, "fast"), post_buckling(e)
    scale = float(np.max(np.abs(ref.curvature(np.linspace(0, 1, 201)))))
    err = abs(float(fast.mean_curvature(s0, s1)) - float(ref.mean_curvature(s0, s1)))
    assert err <= 1e-9 * scale


def test_fast_broadcasts_states_against_intervals() -> None:
    e = np.array([1e-6, 1e-3, 0.3])
    sol = post_buckling(e[:, None], "fast")
    out = sol.mean_curvature(np.array([0.1, 0.5]), np.array([0.2, 0.7]))
    assert out.shape == (3, 2)
    assert post_buckling(e, "fast").mean_curvature(0.5, 0.7).shape == (3,)
    assert post_buckling(0.1, "fast").p.shape == ()


def test_surrogate_is_built_once() -> None:
    assert surrogate() is surrogate()
    assert surrogate().coef.shape[0] < 64  # chopped series


@pytest.mark.parametrize("e", [1e-3, 0.2])
def test_shooting_baseline_agrees_where_it_converges(e: float) -> None:
    shot, ref = shooting.shoot(e), post_buckling(e)
    assert shot.failures == 0
    assert float(shot.p) == pytest.approx(float(ref.p), rel=1e-8)
    assert float(shot.r) == pytest.approx(float(ref.r), rel=1e-7)
    assert float(shot.tip_angle) == pytest.approx(float(ref.tip_angle), rel=1e-7)
    assert float(shot.mean_curvature(0.5, 0.6)) == pytest.approx(
        float(ref.mean_curvature(0.5, 0.6)), rel=1e-7
    )
