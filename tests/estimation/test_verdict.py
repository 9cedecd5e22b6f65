"""Each trial's verdict: ok, suspect with reasons, none with the reason."""

from __future__ import annotations

import math

from estimation.jointfit import JointFit
from estimation.verdict import TrialFacts, Verdict, judge

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


def test_an_interval_wider_than_ten_percent_either_side_is_not_ok() -> None:
    """+-10 %: an interval a belief leaves open holds the truth anywhere, so an ok number must
    keep its typical error at 5 %; one side past the bound is enough."""
    assert judge(fit(half=0.095), FACTS, R).status == "ok"
    lopsided = fit(ci_low=500e3 * 0.97, ci_high=500e3 * 1.12)
    v = judge(lopsided, FACTS, R)
    assert v.status == "suspect"
    assert "+12 %" in v.reasons[0]
    assert "+-10 %" in v.reasons[0]
