"""The record's evidence against a stated point belief (estimation.jointfit.beliefcheck)."""

from __future__ import annotations

import dataclasses

import numpy as np

from palpate.estimation.belief import Belief
from palpate.estimation.contact.law import ContactLaw
from palpate.estimation.jointfit import joint_fit
from palpate.estimation.jointfit.beliefcheck import CONTRADICTED, alternatives
from palpate.estimation.verdict import TrialFacts, judge

R = 3.5e-3
SIGMA = 2e-3  # N, the FBG force channel's noise at 1 pm


def record(law: ContactLaw, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A loading record of 400 kPa to 1.2 N on ``law``, 600 samples, load noise SIGMA."""
    rng = np.random.default_rng(seed)
    u = np.linspace(-0.5e-3, 1.0e-3, 600)
    depth = np.clip(u, 0.0, None)
    P = law.force(400e3, depth)
    keep = P <= 1.2
    u, P = u[keep], P[keep]
    return u, P + rng.normal(0.0, SIGMA, u.size), P * 1e-6


def warned(law_told: ContactLaw, law_true: ContactLaw, seed: int) -> bool:
    u, P, e = record(law_true, seed)
    fit = joint_fit(u, P, e, law_told, sigma_force=SIGMA, contact_guess=0.0)
    assert fit.success, fit.message
    return any(w.startswith(CONTRADICTED) for w in fit.warnings)


def test_a_wrong_thickness_is_flagged_and_the_right_one_is_not() -> None:
    thin = ContactLaw(R, 0.45, 2e-3)
    told_thick = dataclasses.replace(thin, thickness=4e-3)
    assert [warned(told_thick, thin, s) for s in range(3)] == [True] * 3
    assert [warned(thin, thin, s) for s in range(3)] == [False] * 3


def test_the_warning_makes_the_verdict_suspect() -> None:
    thin = ContactLaw(R, 0.45, 2e-3)
    u, P, e = record(thin, 0)
    fit = joint_fit(u, P, e, dataclasses.replace(thin, thickness=4e-3), sigma_force=SIGMA)
    verdict = judge(fit, TrialFacts(), R)
    assert verdict.status == "suspect"
    assert any("prefers a 2 mm layer to the stated 4 mm" in r for r in verdict.reasons)


def test_only_point_beliefs_are_checked() -> None:
    law = ContactLaw(R, 0.45, 10e-3)
    point = Belief.from_law(law)
    said = [text for text, _ in alternatives(point, law)]
    assert len(said) == 5  # half and double the thickness, the other base, nu -+ 0.05
    ranged = dataclasses.replace(point, thickness=(5e-3, 20e-3), poisson=(0.4, 0.5))
    assert [text for text, _ in alternatives(ranged, law)] == [
        "a sliding base to the stated bonded one"
    ]
    assert alternatives(Belief.from_law(ContactLaw(R, 0.45, None)), ContactLaw(R, 0.45)) != []
