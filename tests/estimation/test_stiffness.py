"""The paper's estimator (Eqs. 13-14) and the per-sample statistics of Tables I/II."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from palpate.estimation.beam.section import euler_load
from palpate.estimation.contact.hertz import hertz_modulus
from palpate.estimation.fits.stiffness import (
    EULER_FIXED_PINNED,
    PAPER_OUTLIER_ABOVE,
    StiffnessEstimate,
    paper_estimate,
    summarize,
)

EI = 1.18e-4
R_TIP = 3.5e-3


def hertz_depth(P: float, E: float, nu: float) -> float:
    """Synthetic Hertz curve inverted: the depth at which a sphere on E carries P."""
    return float((3.0 * P * (1.0 - nu**2) / (4.0 * E * math.sqrt(R_TIP))) ** (2.0 / 3.0))


def test_euler_load_of_the_fixed_pinned_sensor() -> None:
    assert pytest.approx(20.19, abs=1e-3) == EULER_FIXED_PINNED
    assert math.tan(math.sqrt(EULER_FIXED_PINNED)) == pytest.approx(
        math.sqrt(EULER_FIXED_PINNED), rel=1e-12
    )
    # Paper sensor: P_cr about 0.95-1.35 N for L = 42-50 mm.
    assert 0.9 < euler_load(EI, 0.050) < euler_load(EI, 0.042) < 1.4


@given(
    E=st.floats(1e3, 5e7),
    nu=st.floats(0.0, 0.5),
    L=st.floats(0.03, 0.07),
    x_c=st.floats(-0.05, 0.05),
)
def test_synthetic_hertz_curve_gives_back_the_modulus(
    E: float, nu: float, L: float, x_c: float
) -> None:
    P = EULER_FIXED_PINNED * EI / L**2
    x_b = x_c + hertz_depth(P, E, nu)
    est = paper_estimate(x_c, x_b, L, EI, R_TIP, nu)
    assert est.success
    assert est.message == "ok"
    assert est.force == pytest.approx(P, rel=1e-14)
    # The relative error comes from rounding the depth into the encoder difference.
    assert est.modulus == pytest.approx(E, rel=1e-9)


def test_given_load_and_section_object() -> None:
    @dataclass(frozen=True)
    class Section:
        EI: float

    E, nu, P = 6e5, 0.45, 1.7
    est = paper_estimate(0.01, 0.01 + hertz_depth(P, E, nu), 0.045, Section(EI), R_TIP, nu, P=P)
    assert est.success
    assert est.force == P
    assert est.modulus == pytest.approx(E, rel=1e-12)
    # Hand value of Eq. 13.
    assert hertz_modulus(1.0, 2e-4, R_TIP, 0.5) == pytest.approx(
        0.75 * 0.75 / math.sqrt(8e-12 * R_TIP)
    )


@pytest.mark.parametrize("delta", [0.0, -1e-4])
def test_no_indentation_is_a_failure_result(delta: float) -> None:
    est = paper_estimate(0.02, 0.02 + delta, 0.045, EI, R_TIP, 0.45)
    assert not est.success
    assert est.modulus is None
    assert est.delta == pytest.approx(delta, abs=1e-15)
    assert "no indentation" in est.message
    assert math.isfinite(est.force)


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ((math.nan, 0.01, 0.045, EI, R_TIP, 0.45), "finite"),
        ((0.0, 0.01, 0.0, EI, R_TIP, 0.45), "length"),
        ((0.0, 0.01, 0.045, -EI, R_TIP, 0.45), "EI"),
        ((0.0, 0.01, 0.045, EI, 0.0, 0.45), "tip_radius"),
        ((0.0, 0.01, 0.045, EI, R_TIP, 0.7), "poisson"),
    ],
)
def test_bad_inputs_raise(args: tuple[float, ...], match: str) -> None:
    with pytest.raises(ValueError, match=match):
        paper_estimate(*args)


def test_bad_load_raises() -> None:
    with pytest.raises(ValueError, match="P must be"):
        paper_estimate(0.0, 1e-4, 0.045, EI, R_TIP, 0.45, P=-1.0)


def test_summary_against_numpy_by_hand() -> None:
    est = np.array([820e3, 1.05e6, 990e3, 1.4e6, 700e3])
    actual = 1023.67e3
    s = summarize(est, actual)
    assert s.count == 5
    assert s.outliers == 0
    assert s.failed == 0
    assert s.mean == pytest.approx(est.mean())
    assert s.median == pytest.approx(np.median(est))
    assert s.rmse == pytest.approx(math.sqrt(sum((x - actual) ** 2 for x in est) / 5))
    srt = np.sort(est)  # 5 values: linear percentiles fall on the 2nd and 4th
    assert s.iqr == pytest.approx(srt[3] - srt[1])
    assert s.relative_error == pytest.approx((est.mean() - actual) / actual)


def test_outlier_rule_and_failures() -> None:
    good = [400e3, 500e3, 600e3]
    failed = StiffnessEstimate(False, None, -1e-4, 1.0, "no indentation")
    items: list[float | StiffnessEstimate | None] = [*good, 3.2e6, 9e6, None, failed, math.nan]
    s = summarize(items, 500e3)
    assert s.count == 3
    assert s.outliers == 2
    assert s.failed == 3
    assert s.mean == pytest.approx(500e3)
    assert s.rmse == pytest.approx(math.sqrt((100e3**2 * 2) / 3))
    # The boundary itself is kept (the paper removed estimates *above* 3 MPa).
    assert summarize([PAPER_OUTLIER_ABOVE], 1e6).count == 1
    # Configurable, and None keeps everything.
    assert summarize(items, 500e3, outlier_above=550e3).count == 2
    assert summarize(items, 500e3, outlier_above=None).count == 5


def test_nothing_left_gives_none_not_nan() -> None:
    s = summarize([5e6, None], 1e6)
    assert s.count == 0
    assert s.outliers == 1
    assert s.failed == 1
    assert s.mean is None
    assert s.rmse is None
    assert s.iqr is None
    assert s.relative_error is None
    with pytest.raises(ValueError, match="judged against"):
        summarize([1e6], 0.0)
