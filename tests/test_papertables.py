"""The paper's tables, their error structure, and the reported reference moduli."""

from __future__ import annotations

import dataclasses

import pytest

from palpate.campaigns.campaign import reported_references
from palpate.config import load, resolve
from palpate.config.scene import SceneConfig
from palpate.reports.papertables import TABLE_I, TABLE_II, ErrorStructure, TableRow, structure


def test_table_one_has_the_structure_the_calibration_aims_at() -> None:
    st = structure(TABLE_I)
    assert st.median_abs_error == pytest.approx(0.188, abs=5e-4)  # sample 11: 263.03 / 323.78
    assert st.spread == pytest.approx(0.447, abs=5e-4)  # sample 3: 225.30 / 504.03
    assert (st.over, st.under) == (3, 8)
    assert st.within_band()
    assert structure(TABLE_II).under == 2


def test_the_band_needs_both_signs_and_both_ranges() -> None:
    assert not ErrorStructure(0.2, 0.4, 11, 0).within_band()
    assert not ErrorStructure(0.05, 0.4, 5, 6).within_band()
    assert not ErrorStructure(0.2, 0.7, 5, 6).within_band()
    assert ErrorStructure(0.2, 0.4, 5, 6).within_band()
    assert TableRow("x", None, 1.0, None, None).relative_error is None


BENCH = load(SceneConfig, resolve("scenes/bench.yaml"))
ROBOT = load(SceneConfig, resolve("scenes/robot.yaml"))


def test_reported_references_are_seeded_per_sample_name() -> None:
    a, b = reported_references(BENCH, 0), reported_references(BENCH, 1)
    assert a == reported_references(BENCH, 0)
    assert a != b
    assert reported_references(ROBOT, 0)["S7"] == a["S7"]  # Table II's phantom is Table I's
    sd = BENCH.fidelity.reference_error_sd
    for s in BENCH.samples:
        ref = a[s.name]
        assert ref is not None
        assert abs(ref / s.modulus - 1) < 4 * sd  # lognormal, sd 0.15
    exact = dataclasses.replace(
        BENCH, fidelity=dataclasses.replace(BENCH.fidelity, reference_error_sd=0)
    )
    assert set(reported_references(exact, 0).values()) == {None}
