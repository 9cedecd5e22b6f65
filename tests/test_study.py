"""The coverage study's statistics (against exact values) and its command on a short study."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from palpate.campaigns.study import (
    TrialErrors,
    binomial_cdf,
    method_stats,
    quantile_interval,
    summarize_study,
    wilson,
)
from palpate.cli import main


def test_wilson_matches_the_closed_form_and_stays_in_0_1() -> None:
    b = wilson(45, 50)
    # Wilson 1927 for p = 0.9, n = 50, z = 1.96: 0.7864 .. 0.9565
    assert b.value == 0.9
    assert b.low == pytest.approx(0.78640, abs=1e-4)
    assert b.high == pytest.approx(0.95652, abs=1e-4)
    assert wilson(0, 10).low == 0.0
    assert wilson(10, 10).high == 1.0
    assert wilson(0, 0).value is None
    with pytest.raises(ValueError, match="successes"):
        wilson(3, 2)


def test_order_statistic_interval_has_its_coverage() -> None:
    n, q = 40, 0.5
    b = quantile_interval(list(range(1, n + 1)), q)
    # the ranks are 1-based order statistics: check their binomial coverage directly
    assert b.low is not None
    assert b.high is not None
    r, s = int(b.low), int(b.high)
    cdf = binomial_cdf(n, q)
    assert cdf[s - 1] - cdf[r - 1] >= 0.95
    # and no tighter: one rank less on top leaves more than 2.5 % above
    assert 1.0 - cdf[s - 2] > 0.025
    assert b.value == 20.5


def test_binomial_cdf_against_exact_sums() -> None:
    from math import comb

    n, p = 30, 0.3
    exact = np.cumsum([comb(n, k) * p**k * (1 - p) ** (n - k) for k in range(n + 1)])
    assert binomial_cdf(n, p) == pytest.approx(exact, rel=1e-12, abs=1e-15)
    assert binomial_cdf(5000, 0.5)[2500] == pytest.approx(0.5056, abs=1e-3)  # no underflow


def test_order_statistic_interval_covers_a_known_median() -> None:
    rng = np.random.default_rng(7)
    held = 0
    for _ in range(400):
        b = quantile_interval(rng.exponential(size=60).tolist(), 0.5)
        assert b.low is not None
        assert b.high is not None
        held += b.low <= np.log(2.0) <= b.high
    assert 0.93 <= held / 400 <= 1.0  # >= 95 % by construction; 400 draws: a few % of noise


def test_too_few_values_leave_a_bound_open() -> None:
    b = quantile_interval([0.1, 0.2, 0.3, 0.4, 0.5], 0.5)
    assert (b.low, b.high) == (None, None)  # 5 values cannot bound a median at 95 %
    assert quantile_interval([], 0.5).value is None
    with pytest.raises(ValueError, match="0 < q < 1"):
        quantile_interval([1.0], 1.0)


def test_method_stats_counts_numbers_errors_and_coverage() -> None:
    actual = [100.0] * 4
    estimates = [110.0, 90.0, None, 100.0]
    intervals = [(105.0, 115.0), (80.0, 120.0), (None, None), (99.0, 101.0)]
    m = method_stats(actual, estimates, intervals)
    assert m.trials == 4
    assert m.with_number.value == 0.75
    assert m.max_abs_rel_error == pytest.approx(0.1)
    assert m.median_abs_rel_error.value == pytest.approx(0.1)
    assert m.coverage is not None
    assert m.coverage.value == pytest.approx(2 / 3)  # two of the three closed intervals hold it


def test_summary_groups_by_sample_then_all() -> None:
    rows = [
        TrialErrors("a", 1e3, 1.1e3, 0.9e3, 1.2e3, 1.5e3),
        TrialErrors("b", 2e3, None, None, None, 2.2e3),
        TrialErrors("a", 1e3, 0.95e3, 0.97e3, 0.99e3, None),
    ]
    s = summarize_study(rows)
    assert [g.name for g in s.per_sample] == ["a", "b"]
    assert s.overall is not None
    assert s.overall.joint.trials == 3
    assert s.per_sample[0].joint.coverage is not None
    assert s.per_sample[0].joint.coverage.value == 0.5
    assert s.per_sample[1].paper.with_number.value == 1.0
    assert json.loads(json.dumps(s.as_dict()))["overall"]["group"] == "all"


@pytest.mark.slow
def test_palpate_study_streams_results_and_reports_json(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = tmp_path / "tiny.yaml"
    scene.write_text(
        "name: tiny\nrobot: robot.yaml\nsamples:\n"
        "  - {name: S8, modulus_kpa: 314.53, poisson: 0.45, thickness_mm: 6.0}\n"
        "campaign: {kind: bench, exposed_lengths_mm: [44.0]}\n",
        encoding="utf-8",
    )
    results = tmp_path / "results.jsonl"
    argv = ["study", "--scene", str(scene), "--repeats", "3", "--executor", "serial"]
    assert main([*argv, "--json", "--results", str(results)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["trials"] == 3
    lines = [json.loads(x) for x in results.read_text(encoding="utf-8").splitlines()]
    assert sorted(x["trial"] for x in lines) == ["S8-straight-downward-L44-r0",
                                                 "S8-straight-downward-L44-r1",
                                                 "S8-straight-downward-L44-r2"]  # fmt: skip
    assert len({x["joint_kpa"] for x in lines}) == 3  # each repeat has its own seed
    overall = out["overall"]["joint"]
    assert overall["trials"] == 3
    assert overall["with_number"]["value"] == 1.0
    assert not (tmp_path / "logs").exists()  # no logs unless asked
    assert main([*argv, "--repeats", "0"]) == 2
