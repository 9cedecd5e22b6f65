"""One answer per sample (issue 41): a campaign's trials of one sample fitted together, in the
run's results beside the per-trial rows, and read back the same from the logs on a resume."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from palpate.cli import main


@pytest.mark.slow
def test_the_bench_campaign_pools_a_samples_five_lengths(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = ["sim", "--campaign", "bench", "--workers", "1", "--no-plots", "--json"]
    code = main([*args, "--out", str(tmp_path), "--limit", "5"])
    assert code == 0
    payload = json.loads(capsys.readouterr().out)
    (s1,) = payload["samples"]
    assert s1["pooled_trials"] == 5
    assert s1["pooled_verdict"] == "ok"
    assert s1["pooled_interval_holds_truth"] is True
    assert abs(s1["pooled_relative_error"]) < 0.03
    widths = [t["joint_ci_kpa"][1] - t["joint_ci_kpa"][0] for t in payload["trials"]]
    pooled_width = s1["pooled_ci_high_kpa"] - s1["pooled_ci_low_kpa"]
    assert pooled_width < min(widths)  # five trials know more than the best one
    with open(Path(payload["run_dir"]) / "samples.csv", encoding="utf-8", newline="") as fh:
        (row,) = list(csv.DictReader(fh))
    assert float(row["pooled_kpa"]) == pytest.approx(s1["pooled_kpa"])
    assert row["pooled_verdict"] == "ok"


@pytest.mark.slow
def test_a_bench_sample_without_a_stated_modulus_gets_its_pooled_answer(tmp_path: Path) -> None:
    """On the bench the modulus is what a lab wants to learn: a sample pressed twice with no
    ``modulus_kpa`` still gets its row, its trials pooled (the emulators on a virtual clock)."""
    from palpate.config.bench import load_bench
    from palpate.lab.trial import plan_bench_trials
    from palpate.services.benchsamples import bench_samples
    from palpate.sim.clock import VirtualClock
    from tests.e2e.test_trial_cli import bench_file, run_on, simulated

    trials = "  - {target: down, sample: S8}\n  - {target: down, sample: S8}\n"
    loaded = load_bench(bench_file(tmp_path, trials))
    assert len(plan_bench_trials(loaded)) == 2
    clock = VirtualClock()
    with simulated(loaded, clock) as sim:
        outcomes = run_on(sim, loaded, clock, tmp_path / "logs")
    (row,) = bench_samples(outcomes, outlier_above=3e6)
    assert row["sample"] == "S8"
    assert row["reference_kpa"] is None
    assert row["pooled_trials"] == 2
    assert row["pooled_kpa"] == pytest.approx(314.53, rel=0.05)  # S8 in the twin's world
    assert row["pooled_ci_low_kpa"] <= row["pooled_kpa"] <= row["pooled_ci_high_kpa"]


@pytest.mark.slow
def test_a_wrong_thickness_is_caught_when_the_trials_span_depths(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The depth-span protocol (docs/estimation.md): a 5 mm layer believed 10 mm thick, pressed
    at 30-50 mm, is flagged by its pooled record with the truth's modulus under the alternative."""
    from palpate.config import resolve

    scene = str(resolve("scenes/mismatch/depth-span.yaml"))
    args = ["sim", "--scene", scene, "--workers", "1", "--no-plots", "--json", "--limit", "5"]
    assert main([*args, "--out", str(tmp_path), "--seed", "5"]) == 0
    payload = json.loads(capsys.readouterr().out)
    (sample,) = payload["samples"]
    assert sample["sample"] == "T5as10-E150"
    assert sample["pooled_verdict"] == "suspect"
    assert "prefers a 5 mm layer to the stated 10 mm" in sample["pooled_reasons"]
    assert sample["pooled_delta_chi2"] > 30
    assert {t["exposed_length_mm"] for t in payload["trials"]} == {30.0, 35.0, 40.0, 45.0, 50.0}
