"""The relaxation fit's contact bracket from the joint fit (``estimation.trial.relaxed``)."""

from __future__ import annotations

from palpate.estimation.jointfit import JointFit
from palpate.estimation.trial.relaxed import contact_bracket


def test_the_bracket_holds_an_x0_refined_past_the_grids_interval() -> None:
    # the values of a relaxing lung trial whose relaxation fit raised "contact must be (low,
    # x0, high) in order" and ended its campaign (invivo/lumen-2.8-relaxing.yaml, seed 0)
    joint = JointFit(
        True, "ok", modulus=2e3, contact=0.09949982305026248,
        contact_low=0.09948869451103981, contact_high=0.09949906356950927,
    )  # fmt: skip
    low, x0, high = contact_bracket(joint)
    assert low <= x0 <= high
    assert (low, x0, high) == (0.09948869451103981, 0.09949982305026248, 0.09949982305026248)
    inside = JointFit(True, "ok", modulus=2e3, contact=0.05, contact_low=0.04, contact_high=0.06)
    assert contact_bracket(inside) == (0.04, 0.05, 0.06)
    bare = JointFit(True, "ok", modulus=2e3, contact=0.05)
    assert contact_bracket(bare) == (0.05, 0.05, 0.05)
