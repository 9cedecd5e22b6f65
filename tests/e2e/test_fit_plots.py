"""The figures that show the fit (``palpate.reports.fitplot``): a trial's record with its fit,
drawn from its log alone (``palpate replay --plot``), and a campaign's estimates with their
intervals."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from palpate.cli import main
from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.reports.fitplot import estimates_with_intervals, record_fit
from palpate.robot.records.log import read_log
from palpate.simulation.trial import TrialOutcome, TrialSpec, run_sim_trial
from palpate.simulation.world import BENCH_COLUMN

STACK = load_stack()
BENCH = load(SceneConfig, resolve("scenes/bench.yaml"))
PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def outcome(tmp_path_factory: pytest.TempPathFactory) -> TrialOutcome:
    spec = TrialSpec(
        "S1-L42", "bench", "S1", 1023.67e3, 0.45, BENCH_COLUMN, "downward", 0.0, 42e-3, 8
    )
    return run_sim_trial(spec, BENCH, STACK, log_dir=tmp_path_factory.mktemp("logs"))


def test_a_trials_fit_is_drawn_from_its_log(outcome: TrialOutcome, tmp_path: Path) -> None:
    path = record_fit(read_log(Path(str(outcome.log_path))), tmp_path / "fit.png")
    assert path.read_bytes()[:8] == PNG


def test_replay_draws_the_fit_and_a_truncated_log_says_why_not(
    outcome: TrialOutcome, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    log = Path(str(outcome.log_path))
    assert main(["replay", str(log), "--plot", str(tmp_path / "r.png")]) == 0
    assert (tmp_path / "r.png").read_bytes()[:8] == PNG
    cut = tmp_path / "cut.jsonl"
    lines = log.read_text(encoding="utf-8").splitlines()
    cut.write_text("\n".join(lines[:200]) + "\n", encoding="utf-8")
    capsys.readouterr()
    assert main(["replay", str(cut), "--plot", str(tmp_path / "c.png")]) == 1  # truncated
    assert "no joint fit to draw" in capsys.readouterr().out
    assert not (tmp_path / "c.png").exists()


def test_a_campaign_draws_every_trials_interval(outcome: TrialOutcome, tmp_path: Path) -> None:
    rows = [outcome.as_dict(), {**outcome.as_dict(), "trial": "no-number", "joint_kpa": None}]
    json.dumps(rows)
    path = estimates_with_intervals(rows, tmp_path / "intervals.png", "two trials")
    assert path.read_bytes()[:8] == PNG
