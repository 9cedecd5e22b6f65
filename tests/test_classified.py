"""A campaign's diagnostic threshold: the trials on the true side, and which of them the
trial's own interval decides (palpate.reports.verdicts.classified)."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

from palpate.estimation.jointfit import JointFit
from palpate.reports.verdicts import classified, classified_line


def _trial(modulus: float, low: float, high: float, true: float) -> Any:
    joint = JointFit(True, "ok", modulus=modulus, ci_low=low, ci_high=high)
    return SimpleNamespace(
        calibration=None, status="suspect", joint=joint, spec=SimpleNamespace(modulus=true)
    )


def test_an_interval_across_the_threshold_does_not_decide_the_side() -> None:
    outcomes = [
        _trial(7e3, 6.5e3, 8e3, 7e3),  # above, and says so
        _trial(5e3, 3e3, 8e3, 7e3),  # the wrong side, its interval across: undecided
        _trial(5e3, 4e3, 5.5e3, 7e3),  # the wrong side, and wrongly sure
        _trial(5e3, 4e3, 5.5e3, 5e3),  # below, and says so
    ]
    c = classified(outcomes, 6e3)
    assert (c["with_number"], c["right_side"]) == (4, 2)
    assert (c["decided"], c["decided_right_side"]) == (3, 2)
    line = classified_line(outcomes, 6e3)[0]
    assert "2/4 trials with a number on the true side" in line
    assert "2/3 of those whose interval lies on one side" in line
