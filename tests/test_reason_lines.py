"""A campaign's summary counts its trials' reasons by kind (palpate.reports.verdicts)."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

from palpate.estimation.verdict import Verdict
from palpate.reports.verdicts import reason_lines


def _trial(status: str, *reasons: str) -> Any:
    return SimpleNamespace(calibration=None, verdict=Verdict(status, reasons))


def test_reasons_that_differ_in_their_figures_count_as_one_kind() -> None:
    thick = (
        "the record contradicts the stated belief: the record prefers a {} mm layer to the "
        "stated {} mm: delta chi^2 = {}"
    )
    outcomes = [
        _trial("suspect", thick.format(5, 10, 125)),
        _trial("suspect", thick.format(5, 10, 14)),
        _trial("suspect", "the layer is compressed by delta/h = 0.436 > 0.2: finite strain"),
        _trial("ok"),
        _trial("none", "tissue too soft for this sensor (2.9 mm at 134 kPa)"),
    ]
    lines = reason_lines(outcomes)
    assert lines[0] == (
        "   2 x suspect: the record contradicts the stated belief: the record prefers a 5 mm "
        "layer to the stated 10 mm"
    )
    assert "   1 x none: tissue too soft for this sensor" in lines
    assert len(lines) == 3


def test_a_kind_whose_figures_differ_is_shown_by_an_example() -> None:
    lines = reason_lines(
        [
            _trial("suspect", "imprecise: the 95 % interval spans -11 % / +9 %, beyond +-10 %"),
            _trial("suspect", "imprecise: the 95 % interval spans -14 % / +12 %, beyond +-10 %"),
        ]
    )
    assert lines == [
        "   2 x suspect: e.g. imprecise: the 95 % interval spans -11 % / +9 %, beyond +-10 %"
    ]
