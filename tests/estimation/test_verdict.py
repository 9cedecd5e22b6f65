"""Each trial's verdict: ok, suspect with reasons, none with the reason."""

from __future__ import annotations

import dataclasses
import math

import pytest

from palpate.estimation.contact.hertz import hertz_force
from palpate.estimation.jointfit import JointFit
from palpate.estimation.reach import Reach, modulus_below
from palpate.estimation.verdict import TrialFacts, Verdict, judge

R = 3.5e-3
BEST = {"thickness": 0.01, "bonded": True, "poisson": 0.45, "compliance": 0.0}


def fit(E: float = 500e3, half: float = 0.03, **kw: object) -> JointFit:
    base = {
        "success": True,
        "message": "ok",
        "modulus": E,
        "ci_low": E * (1 - half),
        "ci_high": E * (1 + half),
        "best": BEST,
    }
    return JointFit(**(base | kw))  # type: ignore[arg-type]


FACTS = TrialFacts(travel_window=2.5e-3, critical_load=1.35)


def test_a_good_fit_of_a_completed_trial_is_ok() -> None:
    v = judge(fit(), FACTS, R)
    assert v == Verdict("ok")
    assert v.has_number
    assert Verdict.from_dict(v.as_dict()) == v


def test_each_suspect_reason_is_named() -> None:
    facts = TrialFacts(
        state="fault",
        reason="FBG stream lost",
        travel_window=2.5e-3,
        critical_load=1.35,
        misalignment=math.radians(4.0),
        misalignment_tolerance=math.radians(2.0),
        compliance_calibrated=False,
    )
    warnings = ("the contact position's interval reaches the record's edge",)
    v = judge(fit(half=0.2, warnings=warnings), facts, R)
    assert v.status == "suspect"
    text = " | ".join(v.reasons)
    for part in ("imprecise", "record's edge", "not calibrated", "4.0 deg beyond", "fault"):
        assert part in text


def test_corrected_validity_flags_do_not_make_a_fit_suspect() -> None:
    corrected = (
        "sample too thin for a half-space: a/h up to 0.2 > 0.1; Dimitriadis "
        "thin-layer correction applied",
    )
    assert judge(fit(warnings=corrected), FACTS, R).status == "ok"
    extrapolated = ("layer ratio sqrt(R delta)/h = 1.2 beyond the Dimitriadis series' range",)
    assert judge(fit(warnings=extrapolated), FACTS, R).status == "suspect"


def test_a_failed_fit_is_none_with_its_message() -> None:
    v = judge(JointFit(False, "no contact: the record ends before the contact"), FACTS, R)
    assert v.status == "none"
    assert not v.has_number
    assert "no contact" in v.reasons[0]


def test_tissue_too_soft_for_the_sensor_is_none_with_the_reason() -> None:
    # no buckling in the travel window and no fit
    facts = TrialFacts(
        "fault",
        "no buckling: travel past contact reached the 2.50 mm limit",
        travel_window=2.5e-3,
        critical_load=1.35,
    )
    v = judge(JointFit(False, "no contact"), facts, R)
    assert v.status == "none"
    assert v.reasons[0].startswith("tissue too soft for this sensor")
    assert "palpate design" in v.reasons[0]
    # a fitted 60 kPa needs ~3 mm to push back P_cr: more than the 2.5 mm window
    v = judge(fit(60e3), FACTS, R)
    assert v.status == "none"
    assert "buckling needs more than the 2.5 mm travel window" in v.reasons[0]
    assert judge(fit(300e3), FACTS, R).status == "ok"


def test_a_window_run_out_bounds_the_modulus_from_above() -> None:
    """The bound is the modulus at which Hertz pushes back exactly P_cr at the least
    indentation the window leaves (window less compliance times P_cr), so any tissue that
    pushed back less there is below it; the verdict states it; unknown nu or compliance, none."""
    reach = Reach(window=2.5e-3, p_cr=1.35, poisson=0.45, compliance=0.2e-3)
    bound = modulus_below(reach, R)
    assert bound is not None
    depth = 2.5e-3 - 0.2e-3 * 1.35
    assert float(hertz_force(bound, depth, R, 0.45)) == pytest.approx(1.35, rel=1e-12)
    assert float(hertz_force(0.99 * bound, depth, R, 0.45)) < 1.35
    assert modulus_below(dataclasses.replace(reach, compliance=None), R) is None
    assert modulus_below(dataclasses.replace(reach, compliance=1.0), R) is None  # takes it all
    facts = TrialFacts(
        "done",
        "no buckling: travel past contact reached the 2.50 mm limit",
        travel_window=2.5e-3,
        critical_load=1.35,
        poisson=0.45,
        compliance_max=0.2e-3,
    )
    v = judge(JointFit(False, "no contact"), facts, R)
    assert v.status == "none"
    assert f"the tissue is below {bound / 1e3:.3g} kPa" in v.reasons[0]


def test_an_interval_wider_than_ten_percent_either_side_is_not_ok() -> None:
    """+-10 %: an interval a belief leaves open holds the truth anywhere, so an ok number must
    keep its typical error at 5 %; one side past the bound is enough."""
    assert judge(fit(half=0.095), FACTS, R).status == "ok"
    lopsided = fit(ci_low=500e3 * 0.97, ci_high=500e3 * 1.12)
    v = judge(lopsided, FACTS, R)
    assert v.status == "suspect"
    assert "+12 %" in v.reasons[0]
    assert "+-10 %" in v.reasons[0]


# -- a sensor that knows its range, and a tip grating's evidence (issue 28) -------------------
LUNG = TrialFacts(travel_window=6e-3, critical_load=18e-3, designed_range=(1e3, 20e3))


def test_an_estimate_outside_the_designed_range_keeps_its_number_as_suspect() -> None:
    v = judge(fit(E=60e3), LUNG, 10e-3)
    assert v.status == "suspect"
    assert v.reasons[0].startswith("above the designed range 1-20 kPa")
    below = judge(fit(E=0.5e3), LUNG, 10e-3)
    assert below.status == "suspect"
    assert below.reasons[0].startswith("below the designed range 1-20 kPa")
    inside = judge(fit(E=10e3), LUNG, 10e-3)
    assert not any("designed range" in r for r in inside.reasons)


def test_an_interval_that_reaches_into_the_range_keeps_its_number() -> None:
    assert judge(fit(E=20.3e3), LUNG, 10e-3).status == "ok"  # 19.7-20.9 kPa reaches 20


def test_buckling_marked_at_a_small_tip_load_is_suspect() -> None:
    early = dataclasses.replace(LUNG, buckling_tip_load=0.7e-3)
    v = judge(fit(E=15e3), early, 10e-3)
    assert v.status == "suspect"
    assert "buckling detected at a tip load of 0.7 mN, 4%" in v.reasons[0]
    late = dataclasses.replace(LUNG, buckling_tip_load=17e-3)
    assert judge(fit(E=15e3), late, 10e-3).status == "ok"


def test_a_bow_measured_against_the_tip_load_beyond_one_percent_is_suspect() -> None:
    bowed = judge(fit(E=15e3), dataclasses.replace(LUNG, bow=0.044), 10e-3)
    assert bowed.status == "suspect"
    assert "w0/L = 4.4%" in bowed.reasons[0]
    straight = dataclasses.replace(LUNG, bow=5e-4)
    assert judge(fit(E=15e3), straight, 10e-3).status == "ok"


def test_an_unverified_orientation_says_what_probing_said() -> None:
    base = dataclasses.replace(FACTS, orientation_verified=False)
    straight = judge(fit(), dataclasses.replace(base, probe_reason=None), R)
    assert "(a straight tube's touches all lie on one line)" in straight.reasons[0]
    slipped = dataclasses.replace(base, probe_reason="normal not measured: 4 of 4 touches slipped")
    v = judge(fit(), slipped, R)
    assert v.status == "suspect"
    assert "(probing: normal not measured: 4 of 4 touches slipped)" in v.reasons[0]
    assert "straight tube" not in v.reasons[0]
