"""The probe's normal uncertainty: scaled up by the touches' own scatter when they scatter more
than assumed, never down (the IK then allows the tolerance plus two of those sigmas; the noisy
mismatch campaign, ``config/scenes/mismatch/noise3pm.yaml``, shows the effect end to end)."""

from __future__ import annotations

import math

import pytest

from palpate.estimation.pose.surface import SurfaceFit
from palpate.robot.probe_fit import allowed_residual
from palpate.robot.probe_fit import scaled_sigma as _scaled_sigma

SIGMA = 10e-6  # m, the touches' assumed uncertainty


def _fit(points: int, rms: float, model: str = "plane") -> SurfaceFit:
    return SurfaceFit(True, "", model, None, rms=rms, normal_sigma=math.radians(0.3), points=points)  # type: ignore[arg-type]


def test_a_scatter_beyond_the_assumed_sigma_widens_the_normal() -> None:
    # 4 touches on a plane: 1 spare; rms 2 sigma -> chi^2/dof = 4 * 4 / 1: 4x the sigma
    assert _scaled_sigma(_fit(4, 2 * SIGMA), SIGMA) == pytest.approx(4 * math.radians(0.3))


def test_a_tight_fit_keeps_the_assumed_sigma() -> None:
    assert _scaled_sigma(_fit(4, 0.1 * SIGMA), SIGMA) == pytest.approx(math.radians(0.3))


@pytest.mark.parametrize(("points", "model"), [(3, "plane"), (4, "sphere")])
def test_without_a_spare_touch_the_assumed_sigma_stands(points: int, model: str) -> None:
    assert _scaled_sigma(_fit(points, 5 * SIGMA, model), SIGMA) == pytest.approx(math.radians(0.3))


def test_the_normals_doubt_widens_the_allowed_residual_only_up_to_five_degrees() -> None:
    """A pose within 2 sigma of the tolerance is indented (its verdict reads the residual), but
    never one past 5 deg, where the indentation stops being normal: a 38 deg sample probed with
    a 17 deg sigma once accepted a pose 34 deg off."""
    tol = math.radians(2.0)
    assert allowed_residual(tol, math.radians(0.5)) == pytest.approx(math.radians(3.0))
    assert allowed_residual(tol, math.radians(17.0)) == pytest.approx(math.radians(5.0))
    assert allowed_residual(math.radians(8.0), math.radians(1.0)) == pytest.approx(
        math.radians(8.0)
    )
