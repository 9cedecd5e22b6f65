"""A relaxing gel on the simulated bench, held after buckling: the relaxation fit, its verdicts,
the log and the replay (issue 27); an elastic gel held the same way reads no relaxation."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest

from palpate.campaigns.resume import outcome_from_log
from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.reports.replay import replay
from palpate.simulation.trial import TrialOutcome, TrialSpec, run_sim_trial
from palpate.simulation.world import BENCH_COLUMN

pytestmark = pytest.mark.slow  # a heavy module fixture: the quick subset leaves it out

STACK = load_stack()
GELS = load(SceneConfig, resolve("scenes/viscoelastic/gels.yaml"))
ELASTIC = load(SceneConfig, resolve("scenes/viscoelastic/elastic-hold.yaml"))


def short_hold(scene: SceneConfig) -> SceneConfig:
    return dataclasses.replace(scene, campaign=dataclasses.replace(scene.campaign, hold_s=3.0))


def spec(trial: str) -> TrialSpec:
    return TrialSpec(
        trial, "bench", "G500", 500e3, 0.45, BENCH_COLUMN, "downward", 0.0, 46e-3, 5,
        indent_speed=2e-3,
    )  # fmt: skip


@pytest.fixture(scope="module")
def relaxing(tmp_path_factory: pytest.TempPathFactory) -> TrialOutcome:
    logs = tmp_path_factory.mktemp("logs")
    return run_sim_trial(spec("G500-v2"), short_hold(GELS), STACK, log_dir=logs)


def test_the_hold_reads_the_relaxed_and_instantaneous_moduli(relaxing: TrialOutcome) -> None:
    assert relaxing.state == "done", relaxing.reason
    fit = relaxing.relaxation
    assert fit is not None
    assert fit.success, fit.message
    assert fit.relaxes
    assert fit.hold == pytest.approx(3.0, abs=0.01)
    # the world: E_inf 500 kPa, E_0 = 500 / 0.7, tau 1 s (the estimator is told none of it)
    assert fit.relaxed == pytest.approx(500e3, rel=0.06)
    assert fit.instantaneous is not None
    assert fit.instantaneous > 1.2 * fit.relaxed
    # the elastic number at 2 mm/s is read too high, and its verdict says why
    assert relaxing.verdict is not None
    assert relaxing.verdict.status == "suspect"
    assert any(r.startswith("relaxes in the hold (3 s: E_0") for r in relaxing.verdict.reasons)
    assert relaxing.relaxed_verdict is not None
    assert relaxing.as_dict()["relaxed_kpa"] == pytest.approx(fit.relaxed / 1e3)


def test_the_log_carries_the_hold_and_replays_to_the_same_estimate(
    relaxing: TrialOutcome,
) -> None:
    path = Path(str(relaxing.log_path))
    lines = [json.loads(x) for x in path.read_text(encoding="utf-8").splitlines()]
    assert any(r.get("kind") == "sample" and r["state"] == "holding" for r in lines)
    record = next(r for r in lines if r.get("kind") == "estimate")
    assert record["relaxation"]["relaxed"] == relaxing.relaxation.relaxed  # type: ignore[union-attr]
    report = replay(path)
    assert report["identical"] is True
    assert report["replayed_relaxation"] == record["relaxation"]
    assert report["replayed_relaxed_verdict"] == record["relaxed_verdict"]


def test_an_elastic_gel_held_the_same_way_reads_no_relaxation(tmp_path: Path) -> None:
    out = run_sim_trial(spec("G500-elastic"), short_hold(ELASTIC), STACK, log_dir=tmp_path)
    assert out.relaxation is not None
    assert out.relaxation.success
    assert not out.relaxation.relaxes
    assert out.relaxed_verdict is not None
    assert out.relaxed_verdict.status == "ok"
    assert out.joint is not None
    assert out.joint.modulus is not None
    assert out.joint.modulus == pytest.approx(500e3, rel=0.05)


def test_a_resumed_campaign_reads_the_relaxation_back_bit_for_bit(relaxing: TrialOutcome) -> None:
    restored = outcome_from_log(Path(str(relaxing.log_path)), relaxing.spec, STACK)
    assert restored is not None
    assert restored.relaxation == relaxing.relaxation
    assert restored.relaxed_verdict == relaxing.relaxed_verdict
