"""What the estimator is told: the belief's grid of hypotheses."""

from __future__ import annotations

import math

import numpy as np
import pytest

from palpate.estimation.belief import CHI_STEP, E_STEP, Belief
from palpate.estimation.contact.law import CHI_MAX, ContactLaw

R = 3.5e-3


def test_a_belief_of_values_is_one_hypothesis_the_law_itself() -> None:
    law = ContactLaw(R, 0.45, 10e-3, bonded=False)
    b = Belief.from_law(law, compliance=1e-4)
    (h,) = b.hypotheses(1e-3)
    assert h.law == law
    assert h.compliance == 1e-4
    assert b.open_keys == ()
    assert b.provisional() == h


def test_a_thickness_range_is_a_grid_in_chi_at_most_chi_step_apart() -> None:
    b = Belief(R, thickness=(5e-3, 20e-3))
    depth = 1e-3
    hs = b.hypotheses(depth)
    inv = np.array([1.0 / h.law.thickness for h in hs if h.law.thickness is not None])
    assert len(inv) == len(hs)
    assert inv.min() == pytest.approx(1 / 20e-3)
    assert inv.max() == pytest.approx(1 / 5e-3)
    chi_steps = np.diff(np.sort(inv)) * math.sqrt(R * depth)
    assert np.all(chi_steps <= CHI_STEP + 1e-12)
    assert b.open_keys == ("thickness",)
    assert 5e-3 < float(b.provisional().law.thickness or 0) < 20e-3


def test_an_unknown_thickness_runs_from_the_half_space_to_the_series_limit() -> None:
    b = Belief(R, thickness=(0.0, math.inf))
    depth = 1.5e-3
    hs = b.hypotheses(depth)
    assert hs[0].law.thickness is None  # the half-space
    thinnest = min(h.law.thickness for h in hs if h.law.thickness is not None)
    assert float(hs[-1].law.layer_ratio(depth)) == pytest.approx(CHI_MAX)
    assert thinnest == pytest.approx(math.sqrt(R * depth) / CHI_MAX)
    assert b.provisional().law.thickness is None


def test_open_bonding_poisson_and_compliance_multiply_the_grid() -> None:
    b = Belief(R, poisson=(0.4, 0.5), bonded=(True, False), compliance=(0.0, 1e-5))
    hs = b.hypotheses(1e-3, 1.0)
    nus = sorted({h.law.poisson for h in hs})
    cs = sorted({h.compliance for h in hs})
    assert len(hs) == 2 * len(nus) * len(cs)
    assert {h.law.bonded for h in hs} == {True, False}
    # neighbours move E by at most E_STEP: through 1/(1 - nu^2), through the depth c P_max
    ratios = np.diff(np.log([1 / (1 - nu**2) for nu in nus]))
    assert np.all(ratios <= E_STEP + 1e-12)
    assert nus[0] == 0.4
    assert nus[-1] == 0.5
    assert np.all(1.5 * np.diff(cs) * 1.0 / 1e-3 <= E_STEP + 1e-12)
    assert cs[0] == 0.0
    assert cs[-1] == 1e-5
    assert set(b.open_keys) == {"bonded", "poisson", "compliance"}


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"poisson": (0.5, 0.4)}, "poisson"),
        ({"poisson": (0.4, 0.6)}, "poisson"),
        ({"thickness": (0.0, 0.0)}, "thickness"),
        ({"compliance": (-1e-4, 0.0)}, "compliance"),
        ({"bonded": ()}, "bonded"),
        ({"bonded": (True, True)}, "bonded"),
    ],
)
def test_bad_beliefs_raise(kwargs: dict[str, object], match: str) -> None:
    with pytest.raises(ValueError, match=match):
        Belief(R, **kwargs)  # type: ignore[arg-type]
