"""One answer per sample (issue 41): a campaign's trials of one sample fitted together, in the
run's results beside the per-trial rows, and read back the same from the logs on a resume."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from palpate.cli import main


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
