"""The load's lean from a loading record's strains (issue 25): a slipping tip's lateral load is
detected from the first touch; a pinned tip (aligned, or sticking) shows none; the verdict
requires a verified orientation for ``ok``."""

from __future__ import annotations

import math

import numpy as np
import pytest

from palpate.estimation.beam.section import euler_load
from palpate.estimation.beam.states import onset_mode
from palpate.estimation.jointfit import JointFit
from palpate.estimation.pose.misalignment import (
    DETECT_CHI2,
    Lean,
    capacity,
    lateral_shape,
    measure_lean,
)
from palpate.estimation.verdict import TrialFacts, judge

EI, EA, DY = 1.18e-4, 9.7e3, 1.53e-4  # the shipped sensor's section (N m^2, N, m)
L = 0.042
FROM_TIP = np.array([[8.5e-3, 11.5e-3], [16.5e-3, 19.5e-3], [24.5e-3, 27.5e-3]])
NOISE = 2.4e-6  # 1 pm over 0.424 pm/ue
ARCS = np.stack([L - FROM_TIP[:, 1], L - FROM_TIP[:, 0]], axis=1)


def slipping(lean_deg: float, seed: int) -> np.ndarray:
    """A free tip's record: axial load to 0.9 of its capacity, a lateral load P tan(lean)."""
    P = np.linspace(0.0, 0.9, 300) * capacity(EI, L)
    y = -P[:, None] / EA + math.tan(math.radians(lean_deg)) * lateral_shape(P, L, FROM_TIP, EI, DY)
    return y + np.random.default_rng(seed).normal(0.0, NOISE, y.shape)


def pinned(w0_over_l: float, seed: int) -> np.ndarray:
    """An imperfect pinned beam up to 0.95 P_cr: axial strain and the onset mode's bow growing
    as w0 P / (P_cr - P) (the amplitude z ~ w/L in the onset mode's units)."""
    p_cr = euler_load(EI, L)
    P = np.linspace(0.0, 0.95, 300) * p_cr
    z = w0_over_l * P / (p_cr - P)
    y = -P[:, None] / EA + z[:, None] * onset_mode(ARCS, L, DY)[None, :]
    return y + np.random.default_rng(seed).normal(0.0, NOISE, y.shape)


def measure(y: np.ndarray) -> Lean:
    return measure_lean(y, np.full(y.shape[0], L), FROM_TIP, EA, EI, DY)


@pytest.mark.parametrize("lean_deg", [-5.0, 0.5, 3.0, 10.0])
def test_a_slipping_tips_lateral_load_is_detected(lean_deg: float) -> None:
    lean = measure(slipping(lean_deg, seed=1))
    assert lean.success, lean.message
    assert lean.lateral
    assert lean.aligned_chi2 > DETECT_CHI2
    assert math.copysign(1.0, lean.lean) == math.copysign(1.0, lean_deg)  # the side it bends to
    assert lean.load_share < 1.0  # a free tip's loads stay below its capacity


@pytest.mark.parametrize("w0_over_l", [0.0, 0.002, 0.01])
def test_a_pinned_tip_shows_no_lateral_load(w0_over_l: float) -> None:
    lean = measure(pinned(w0_over_l, seed=2))
    assert lean.success, lean.message
    assert not lean.lateral
    assert lean.aligned_chi2 < DETECT_CHI2
    assert lean.load_share > 1.0  # the pinned tip carried more than a free one could


def test_the_lateral_shape_is_the_small_load_beam_column() -> None:
    """h -> -dy P d / EI (mean d over each grating) as kL -> 0, and grows without bound at the
    capacity."""
    P = np.array([1e-6 * capacity(EI, L)])
    mean_d = FROM_TIP.mean(axis=1)
    assert lateral_shape(P, L, FROM_TIP, EI, DY)[0] == pytest.approx(
        -DY * P[0] * mean_d / EI, rel=1e-6
    )
    near = lateral_shape(np.array([0.999 * capacity(EI, L)]), L, FROM_TIP, EI, DY)
    assert np.all(
        np.abs(near)
        > 100 * np.abs(lateral_shape(np.array([0.1 * capacity(EI, L)]), L, FROM_TIP, EI, DY))
    )


def test_too_few_rows_and_bad_input() -> None:
    short = measure(pinned(0.002, seed=3)[:5])
    assert not short.success
    assert "the fit needs" in short.message
    assert not short.lateral
    with pytest.raises(ValueError, match="strains"):
        measure_lean(np.zeros((10, 2)), np.full(10, L), FROM_TIP, EA, EI, DY)
    with pytest.raises(ValueError, match="EA and EI"):
        measure_lean(np.zeros((10, 3)), np.full(10, L), FROM_TIP, -1.0, EI, DY)


def _ok_fit() -> JointFit:
    best = {"thickness": 0.01, "bonded": True, "poisson": 0.45, "compliance": 0.0}
    return JointFit(True, "ok", modulus=5e5, ci_low=4.9e5, ci_high=5.1e5, best=best)  # type: ignore[arg-type]


def test_ok_requires_a_verified_orientation() -> None:
    facts = TrialFacts(travel_window=2.5e-3, critical_load=1.35)
    assert judge(_ok_fit(), facts, 3.5e-3).status == "ok"
    quiet = Lean(True, "", 0.0, math.radians(0.3), 200, 5.0, 1.0)
    unverified = judge(_ok_fit(), TrialFacts(orientation_verified=False, lean=quiet), 3.5e-3)
    assert unverified.status == "suspect"
    assert any(r.startswith("orientation unverified") for r in unverified.reasons)
    slid = Lean(True, "", math.radians(2.0), math.radians(1.0), 200, 0.5, 2e4)
    for verified in (True, False):
        v = judge(_ok_fit(), TrialFacts(orientation_verified=verified, lean=slid), 3.5e-3)
        assert v.status == "suspect"
        assert any(r.startswith("misaligned: the strains show a lateral load") for r in v.reasons)


def test_a_slide_names_the_angle_its_path_shows_even_without_a_number() -> None:
    """The verdict reads the slipping tip's misalignment (``estimation.pose.slip_path``); a trial
    with no modulus (its load never reached the pinned beam's) says it slid as well."""
    slid = Lean(True, "", math.radians(2.0), math.radians(1.0), 200, 0.5, 2e4,
                math.radians(12.2), math.radians(0.5))  # fmt: skip
    assert slid.measured
    v = judge(_ok_fit(), TrialFacts(lean=slid), 3.5e-3)
    assert v.status == "suspect"
    assert any(r.startswith("misaligned: misalignment 12.2 +- 0.5 deg") for r in v.reasons)
    none = judge(None, TrialFacts(lean=slid), 3.5e-3)
    assert none.status == "none"
    assert none.reasons[0].startswith("no estimate")
    assert any(r.startswith("misaligned: misalignment 12.2") for r in none.reasons)
    assert Lean.from_record(slid.record()) == slid
    quiet = Lean(True, "", 0.0, math.radians(0.3), 200, 5.0, 1.0)
    assert judge(None, TrialFacts(lean=quiet), 3.5e-3).reasons == ("no estimate: no fit",)
    assert "misalignment" not in quiet.record()


def test_a_measured_misalignment_is_verified_within_the_tolerance_at_two_sigmas() -> None:
    tol = math.radians(2.0)

    def facts(mis_deg: float, sigma_deg: float) -> TrialFacts:
        return TrialFacts(
            misalignment=math.radians(mis_deg),
            misalignment_tolerance=tol,
            misalignment_sigma=math.radians(sigma_deg),
        )

    assert judge(_ok_fit(), facts(0.4, 0.3), 3.5e-3).status == "ok"
    loose = judge(_ok_fit(), facts(1.6, 0.3), 3.5e-3)
    assert loose.status == "suspect"
    assert any("not verified within" in r for r in loose.reasons)
    beyond = judge(_ok_fit(), facts(2.5, 0.3), 3.5e-3)
    assert any("beyond the campaign's tolerance" in r for r in beyond.reasons)
    assert not any("not verified within" in r for r in beyond.reasons)  # said once
    # a map keeps the interval of a probe suspect for a small measured tilt alone, by how these
    # reasons begin (maps.probes.TILT_REASON): a renamed reason must fail here
    from palpate.maps.probes import TILT_REASON

    assert all(r.startswith(TILT_REASON) for r in (*loose.reasons, *beyond.reasons))


def test_rows_with_every_grating_inside_the_tube_are_left_out_not_nan() -> None:
    """Rows whose gratings are all still inside the tube (an advance taken against a drift
    estimated far beyond the record's) have no onset mode: left out, never a NaN."""
    y = pinned(0.002, seed=4)
    lengths = np.full(y.shape[0], L)
    lengths[:40] = 5e-3  # every grating (8.5-27.5 mm from the tip) inside the tube
    with np.errstate(invalid="raise", divide="raise"):
        lean = measure_lean(y, lengths, FROM_TIP, EA, EI, DY)
    assert lean.success
    assert math.isfinite(lean.aligned_chi2)
    assert not lean.lateral
