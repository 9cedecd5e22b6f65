"""The per-sample pooled fit (issue 41): trials' chi^2 curves in E summed with each trial's own
contact point, the pooled estimate and interval, and the pooled belief check."""

from __future__ import annotations

import numpy as np
import pytest

from palpate.estimation.jointfit.pooling import FORM, STATED, Curve, Terms, pool


def parabola(E0: float, sigma: float, floor: float = 0.0) -> Curve:
    """A trial's curve whose chi^2 in E is ((E - E0) / sigma)^2 + floor: the best contact
    position, and a worse one whose E is 10 % higher (the profile takes the lower envelope)."""
    E = np.array([E0, 1.1 * E0])
    return Curve(E, np.array([floor, floor + 1e3]), np.full(2, sigma**-2))


def test_two_trials_pool_to_their_weighted_mean_with_a_narrower_interval() -> None:
    a = Terms(100e3, 0.0, {STATED: parabola(100e3, 2e3)})
    b = Terms(110e3, 0.0, {STATED: parabola(110e3, 4e3)})
    p = pool([a, b])
    weighted = (100e3 / 2e3**2 + 110e3 / 4e3**2) / (1 / 2e3**2 + 1 / 4e3**2)
    assert p.modulus == pytest.approx(weighted, rel=2e-3)
    sigma = (1 / 2e3**2 + 1 / 4e3**2) ** -0.5
    assert p.ci_low == pytest.approx(weighted - 1.96 * sigma, rel=3e-3)
    assert p.ci_high == pytest.approx(weighted + 1.96 * sigma, rel=3e-3)
    assert p.covers(weighted)
    assert p.contradiction is None


def test_the_other_model_form_and_the_model_form_bound_widen_the_interval() -> None:
    plain = pool([Terms(100e3, 0.0, {STATED: parabola(100e3, 2e3)})] * 3)
    forms = pool(
        [Terms(100e3, 0.0, {STATED: parabola(100e3, 2e3), FORM: parabola(104e3, 2e3)})] * 3
    )
    bound = pool([Terms(100e3, 0.05, {STATED: parabola(100e3, 2e3)})] * 3)
    assert forms.ci_high is not None
    assert plain.ci_high is not None
    assert forms.ci_high > plain.ci_high + 3e3
    assert bound.ci_low is not None
    assert plain.ci_low is not None
    assert bound.ci_low < plain.ci_low - 3e3


def test_an_alternative_that_fits_the_pooled_record_better_contradicts_the_belief() -> None:
    alt = "a 5 mm layer to the stated 10 mm"

    def trial(gain: float) -> Terms:
        curves = {STATED: parabola(100e3, 2e3, floor=gain), alt: parabola(80e3, 2e3)}
        return Terms(100e3, 0.0, curves)

    p = pool([trial(4.0)] * 3)
    assert p.gains[alt] == pytest.approx(12.0, abs=0.1)
    assert p.contradiction is not None
    assert alt in p.contradiction
    weak = pool([trial(4.0), trial(-1.0)])  # 3 in all: within the margin
    assert weak.gains[alt] == pytest.approx(3.0, abs=0.1)
    assert weak.contradiction is None


def test_one_trial_is_not_a_pool() -> None:
    p = pool([Terms(100e3, 0.0, {STATED: parabola(100e3, 2e3)})])
    assert p.modulus is None
    assert "needs 2" in p.message
