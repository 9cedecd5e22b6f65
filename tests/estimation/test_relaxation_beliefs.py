"""The relaxation fit over the belief's hypotheses, the belief check on the relaxed curve, the
verdict that lets relaxation explain the elastic check's alarm, and the memory basis in runs
(``estimation.relaxation.beliefs``, ``estimation.relaxation.spectrum``, ``estimation.verdict``).

Unit tests: the records are made with the estimator's own contact law (the evidence is the
scenes', docs/viscoelastic.md)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from palpate.estimation.belief import Belief
from palpate.estimation.contact.law import ContactLaw
from palpate.estimation.jointfit import JointFit
from palpate.estimation.jointfit.beliefcheck import CONTRADICTED
from palpate.estimation.relaxation import (
    RelaxationFit,
    RelaxationRecord,
    fit_over_beliefs,
    fit_relaxation,
    memory_basis,
)
from palpate.estimation.relaxation.beliefs import thinned
from palpate.estimation.relaxation.pooled import pool_relaxed
from palpate.estimation.verdict import TrialFacts, judge
from palpate.sim.viscoelastic import StandardLinearSolid, force_history

R = 2e-3
E_INF = 400e3
SIGMA = 0.004  # N
DT = 4e-3
CONTACT = (-20e-6, 0.0, 20e-6)


class Elastic:
    def __init__(self, law: ContactLaw, modulus: float) -> None:
        self.law, self.modulus = law, modulus

    def force_and_stiffness_at(self, delta: float) -> tuple[float, float]:
        f, df = self.law.shape(np.array([delta]))
        return float(self.modulus * f[0]), float(self.modulus * df[0])


def record(law: ContactLaw, seed: int = 0) -> RelaxationRecord:
    """A ramp to 0.6 mm at 0.5 mm/s from 0.2 mm before contact, then 6 s at rest, of a standard
    linear solid on ``law``; the load with white noise."""
    relax = StandardLinearSolid(0.5, 0.6)
    t = np.arange(0.0, 0.8e-3 / 0.5e-3 + 6.0, DT)
    u = np.minimum(t * 0.5e-3, 0.8e-3) - 0.2e-3
    force = force_history(relax, Elastic(law, E_INF / relax.ratio), t, np.maximum(u, 0.0))
    noisy = force + np.random.default_rng(seed).normal(0.0, SIGMA, t.size)
    n = t.size
    return RelaxationRecord(t, noisy, u, np.full(n, SIGMA), np.full(n, 1e-7), 6.0)


def belief(poisson: tuple[float, float], thickness: float = 10e-3) -> Belief:
    return Belief(R, poisson=poisson, thickness=(thickness, thickness))


@pytest.mark.slow
def test_an_open_poisson_range_is_carried_into_the_relaxed_interval() -> None:
    truth = ContactLaw(R, 0.49, 10e-3, True)
    rec = record(truth)
    exact = fit_over_beliefs(rec, belief((0.45, 0.49)), CONTACT, E_INF)
    assert exact.success, exact.message
    assert exact.covers(E_INF)
    # the law is exact here: the record itself rules the far end of the range out
    assert exact.hypotheses == 4
    assert 1 <= exact.plausible < 4
    # a law 1 % uncertain cannot: every hypothesis is plausible, the envelope holds both ends
    bounded = fit_over_beliefs(rec, belief((0.45, 0.49)), CONTACT, E_INF, model_form=0.01)
    assert bounded.plausible == 4
    assert bounded.covers(E_INF)
    assert bounded.relaxed_low is not None
    assert bounded.relaxed_high is not None
    for nu in (0.45, 0.49):
        end = fit_relaxation(rec, dataclasses.replace(truth, poisson=nu), CONTACT, E_INF)
        assert end.relaxed is not None
        assert bounded.relaxed_low <= end.relaxed <= bounded.relaxed_high
    assert not any(w.startswith(CONTRADICTED) for w in bounded.warnings)


def test_a_point_belief_is_one_fit() -> None:
    law = ContactLaw(R, 0.45, 10e-3, True)
    rec = record(law, seed=1)
    once = fit_over_beliefs(rec, belief((0.45, 0.45)), CONTACT, E_INF)
    alone = fit_relaxation(rec, law, CONTACT, E_INF)
    assert once.hypotheses == 1
    assert once.plausible == 1
    assert (once.relaxed, once.relaxed_low, once.relaxed_high) == (
        alone.relaxed,
        alone.relaxed_low,
        alone.relaxed_high,
    )


def test_the_relaxed_record_contradicts_a_wrong_thickness() -> None:
    rec = record(ContactLaw(R, 0.45, 2.5e-3, True), seed=2)
    wrong = fit_over_beliefs(rec, belief((0.45, 0.45), thickness=5e-3), CONTACT, E_INF)
    said = [w for w in wrong.warnings if w.startswith(CONTRADICTED)]
    assert said, wrong.warnings
    assert "a 2.5 mm layer to the stated 5 mm" in said[0]
    right = fit_over_beliefs(rec, belief((0.45, 0.45), thickness=2.5e-3), CONTACT, E_INF)
    assert not any(w.startswith(CONTRADICTED) for w in right.warnings), right.warnings


def test_relaxation_explains_the_elastic_checks_alarm() -> None:
    alarm = f"{CONTRADICTED} belief: the record prefers a 40 mm layer to the stated 20 mm: 30"
    joint = JointFit(
        True, "ok", modulus=2e3, ci_low=1.9e3, ci_high=2.1e3, warnings=(alarm,), best={}
    )
    relaxing = RelaxationFit(True, "ok", relaxed=1.5e3, relaxes=True, hold=5.0)
    facts = TrialFacts(relaxation=relaxing)
    assert alarm not in judge(joint, facts, 10e-3).reasons
    elastic = TrialFacts(relaxation=dataclasses.replace(relaxing, relaxes=False))
    assert alarm in judge(joint, elastic, 10e-3).reasons
    relaxed_alarm = f"{CONTRADICTED} belief: the relaxed record prefers a 10 mm layer: 40"
    said = dataclasses.replace(relaxing, warnings=(relaxed_alarm,))
    assert relaxed_alarm in judge(joint, TrialFacts(relaxation=said), 10e-3).reasons


@pytest.mark.parametrize("tau", [0.008, 0.05, 2.0])
def test_the_memory_basis_in_runs_is_the_recursion(tau: float) -> None:
    """Ticks of 4 ms, then blocks of 40 ms (a held record's), one odd step between: the scan
    (cut where exp(s dt/tau) would overflow) is the row-by-row recursion."""
    t = np.r_[np.arange(900) * 4e-3, 3.6 + 0.022 + np.arange(300) * 0.04]
    shape = np.maximum(np.sin(t), 0.0) ** 1.5
    taus = np.array([tau, 10 * tau])
    scanned = memory_basis(t, shape, taus)
    manual = np.zeros_like(scanned)
    for k, tk in enumerate(taus):
        h, prev = 0.0, 0.0
        for i in range(t.size):
            x = (t[i] - t[i - 1]) / tk if i else 0.0
            h = np.exp(-x) * h + (-np.expm1(-x) / x if x > 0 else 1.0) * (shape[i] - prev)
            prev = shape[i]
            manual[i, k] = h
    np.testing.assert_allclose(scanned, manual, rtol=1e-10, atol=1e-13)


def test_a_samples_relaxed_modulus_is_the_typical_trials() -> None:
    def trial(value: float, down: float, up: float) -> RelaxationFit:
        return RelaxationFit(True, "ok", value, value - down, value + up, relaxes=True)

    fits = [trial(1.00e3, 50.0, 60.0), trial(1.04e3, 40.0, 80.0), trial(1.30e3, 90.0, 70.0)]
    pooled = pool_relaxed([*fits, RelaxationFit(False, "no hold in the record")])
    assert pooled.trials == 3
    assert pooled.modulus == pytest.approx(1.04e3)  # the median: one odd trial does not pull
    assert (pooled.ci_low, pooled.ci_high) == pytest.approx((1.04e3 - 50.0, 1.04e3 + 70.0))
    assert pool_relaxed(fits[:1]).modulus is None


def test_an_open_belief_is_fitted_at_a_few_points_of_each_property() -> None:
    """An unknown thickness, either base and a Poisson range: 408 hypotheses on the joint fit's
    grid, 32 fitted, every property's ends among them."""
    wide = Belief(R, poisson=(0.45, 0.49), thickness=(0.0, float("inf")), bonded=(True, False))
    grid = wide.hypotheses(0.6e-3, 0.4)
    kept = thinned(grid)
    assert len(kept) <= 4 * 2 * 4 < len(grid)
    for values in (lambda h: h.law.thickness or 0.0, lambda h: h.law.poisson):
        assert {min(map(values, grid)), max(map(values, grid))} <= set(map(values, kept))
    assert thinned(belief((0.45, 0.49)).hypotheses(0.6e-3, 0.4)) == list(
        belief((0.45, 0.49)).hypotheses(0.6e-3, 0.4)
    )
