"""The joint fit with what is not known: compliance, thickness and bonding ranges, a contact
anywhere in the record, and the interval's coverage when the belief is a range (seeded)."""

from __future__ import annotations

import numpy as np
import pytest

from palpate.estimation.belief import Belief
from palpate.estimation.contact.law import ContactLaw
from palpate.estimation.jointfit import joint_fit
from palpate.estimation.jointfit.envelope import BEFORE_WARNING

R = 3.5e-3
EA = 9.7e3
L = 42e-3
SIGMA_P = 0.015  # N
Q = 20e-3 / 4096
CAP = 1.35  # N: the buckling load


def record(
    E: float,
    x0: float,
    rng: np.random.Generator,
    *,
    law: ContactLaw,
    compliance: float = 0.0,
    before: float = 0.8e-3,
    after: float = 1.6e-3,
    n: int = 500,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Stage advance u from ``before`` ahead of contact x0 to ``after`` past it; the tissue, the
    beam (P L / EA, capped at CAP, past which the beam shortens) and the rig's compliance share
    the advance: u - x0 = delta + e + c P. Encoder-quantised; load noise SIGMA_P."""
    u = np.round(np.linspace(x0 - before, x0 + after, n) / Q) * Q
    delta = np.linspace(0.0, 5e-3, 20001)
    P = np.minimum(law.force(E, delta), CAP)
    k = int(np.searchsorted(P, CAP))
    reach = delta[:k] + compliance * P[:k] + P[:k] * L / EA  # u - x0 on the rising part
    w = u - x0
    d = np.interp(w, reach, delta[:k], left=0.0, right=delta[k - 1])
    force = np.where(w > reach[-1], CAP, law.force(E, d))
    e = np.where(w > reach[-1], w - d - compliance * CAP, force * L / EA)
    e = np.where(w > 0, e, 0.0)
    force = np.where(w > 0, force, 0.0)
    return u, force + rng.normal(0.0, SIGMA_P, n), e


LAW = ContactLaw(R, 0.45, 10e-3)


def fit(u: np.ndarray, P: np.ndarray, e: np.ndarray, belief: Belief | ContactLaw, **kw: object):  # type: ignore[no-untyped-def]
    return joint_fit(u, P, e, belief, sigma_force=SIGMA_P, encoder_resolution=Q, **kw)  # type: ignore[arg-type]


def test_a_calibrated_compliance_is_taken_out_of_the_depth() -> None:
    rng = np.random.default_rng(1)
    c = 1e-4  # m/N: a 10 N/mm tube tip
    u, P, e = record(1.4e6, 20e-3, rng, law=LAW, compliance=c)
    told = fit(u, P, e, Belief(R, thickness=(10e-3, 10e-3), compliance=(c, c)))
    rigid = fit(u, P, e, LAW)
    assert told.success
    assert told.covers(1.4e6)
    assert abs(float(told.modulus or 0) / 1.4e6 - 1) < 0.05
    assert rigid.modulus is not None
    assert rigid.modulus < 0.8 * 1.4e6  # a rigid rig assumed: far too soft, outside its interval
    assert not rigid.covers(1.4e6)


def test_an_uncalibrated_compliance_range_widens_the_interval_to_hold_the_truth() -> None:
    rng = np.random.default_rng(2)
    u, P, e = record(1.4e6, 20e-3, rng, law=LAW, compliance=0.8e-4)
    ranged = fit(u, P, e, Belief(R, thickness=(10e-3, 10e-3), compliance=(0.0, 1e-4)))
    assert ranged.covers(1.4e6)
    assert ranged.profiled == ("compliance",)
    assert ranged.hypotheses > 3  # as fine as E's sensitivity to c requires


def test_the_contact_is_found_over_the_whole_record_whatever_the_guess() -> None:
    rng = np.random.default_rng(3)
    u, P, e = record(300e3, 20e-3, rng, law=LAW, before=2.5e-3)
    late = fit(u, P, e, LAW, contact_guess=21.5e-3)  # 1.5 mm late: outside the old +-1 mm
    none = fit(u, P, e, LAW)
    assert late.success
    assert none.success
    assert late.contact == pytest.approx(20e-3, abs=30e-6)
    assert late.modulus == pytest.approx(float(none.modulus or 0), rel=1e-6)
    assert late.covers(300e3)


def test_a_record_that_starts_in_contact_is_fitted_and_flagged() -> None:
    rng = np.random.default_rng(4)
    u, P, e = record(300e3, 20e-3, rng, law=LAW, before=0.0)
    keep = u > 20.3e-3  # the record starts 0.3 mm past the contact
    r = fit(u[keep], P[keep], e[keep], LAW)
    assert r.success
    assert r.contact is not None
    assert r.contact < float(u[keep].min())
    assert any(w.startswith(BEFORE_WARNING) for w in r.warnings)
    assert abs(float(r.modulus or 0) / 300e3 - 1) < 0.1


def test_a_record_that_ends_at_the_contact_has_no_estimate() -> None:
    rng = np.random.default_rng(5)
    u, P, e = record(300e3, 20e-3, rng, law=LAW, before=1.5e-3, after=0.01e-3)
    r = fit(u, P, e, LAW)
    assert not r.success
    assert r.message.startswith("no contact")


def test_a_thickness_range_is_profiled_and_holds_the_truth_at_its_edge() -> None:
    rng = np.random.default_rng(6)
    thin = ContactLaw(R, 0.45, 5e-3)
    u, P, e = record(350e3, 20e-3, rng, law=thin)
    r = fit(u, P, e, Belief(R, thickness=(5e-3, 20e-3)))
    assert r.success
    assert r.profiled == ("thickness",)
    assert r.covers(350e3)
    assert r.best is not None
    assert 5e-3 <= float(r.best["thickness"]) <= 20e-3
    told = fit(u, P, e, thin)  # the same record, the thickness known
    assert told.ci_high is not None
    assert r.ci_high is not None
    assert r.ci_high - float(r.ci_low or 0) > told.ci_high - float(told.ci_low or 0)


def test_the_model_form_bound_is_reported_and_grows_with_depth() -> None:
    rng = np.random.default_rng(7)
    stiff = fit(*record(2.6e6, 20e-3, rng, law=LAW), LAW)
    soft = fit(*record(150e3, 20e-3, rng, law=LAW), LAW)
    assert stiff.model_form is not None
    assert soft.model_form is not None
    assert 0 < stiff.model_form < soft.model_form < 0.1


@pytest.mark.slow
def test_coverage_with_open_thickness_and_bonding_is_at_least_90_percent() -> None:
    rng = np.random.default_rng(8)
    belief = Belief(R, thickness=(5e-3, 20e-3), bonded=(True, False))
    covered = 0
    trials = 24
    for i in range(trials):
        h = float(rng.uniform(5e-3, 20e-3))
        law = ContactLaw(R, 0.45, h, bonded=bool(i % 2))
        E = float(np.exp(rng.uniform(np.log(200e3), np.log(2e6))))
        u, P, e = record(E, 20e-3, rng, law=law, n=300)
        covered += fit(u, P, e, belief).covers(E)
    assert covered >= 0.9 * trials


def test_every_value_the_belief_leaves_open_keeps_its_own_region() -> None:
    """Two hypotheses (two Poisson ratios of the belief) on one contact grid: the record fits the
    first far better (its RSS 100 below), yet the interval holds the second's E too: the
    closed forms' own error can make the record prefer a wrong value (docs/lung.md)."""
    import numpy as np

    from palpate.estimation.jointfit.profile import read_family

    grid = np.linspace(0.0, 1e-3, 11)
    bowl = (grid - 5e-4) ** 2 * 1e8  # RSS rising away from the grid's middle
    near = (np.full(11, 10e3), np.zeros(11), bowl, np.full(11, 1e-4))  # E 10 kPa, best fit
    far = (np.full(11, 11e3), np.zeros(11), bowl + 100.0, np.full(11, 1e-4))  # 11 kPa, worse
    profile, _ = read_family([near, far], [0, 1], grid, (4.0, 1.0), False, False)
    assert profile is not None
    assert profile.modulus == 10e3  # the best point is still the record's preference
    assert profile.ci_low < 10e3
    assert profile.ci_high > 11e3  # the second hypothesis's E, though its RSS is 100 above
    alone, _ = read_family([near], [0], grid, (4.0, 1.0), False, False)
    assert alone is not None
    assert alone.ci_high < 11e3  # the first hypothesis alone does not reach the second's E
