"""A relaxing lung-like layer through the lung sensor, held after buckling (issue 41): the
relaxation fit reads the tip grating's load, carries the open Poisson ratio into its interval,
and the belief check on the relaxed curve does not blame the relaxation on the thickness."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from palpate.campaigns.campaign import campaign_trials
from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.estimation.jointfit.beliefcheck import CONTRADICTED
from palpate.reports.replay import replay
from palpate.simulation.trial import TrialOutcome, run_sim_trial

pytestmark = pytest.mark.slow  # a heavy module fixture: the quick subset leaves it out

LUNG = load(SceneConfig, resolve("scenes/lung/relaxing.yaml"))
STACK = load_stack(LUNG.robot)


@pytest.fixture(scope="module")
def relaxing(tmp_path_factory: pytest.TempPathFactory) -> TrialOutcome:
    """N4: 1.6 kPa relaxed, nu 0.49 told [0.45, 0.49], 10 mm told right, an SLS of 0.3 s."""
    spec = next(
        s
        for s in campaign_trials(LUNG, STACK, 0)
        if s.sample == "N4" and s.tube.name == "bent15" and s.orientation == "sideways"
    )
    logs = tmp_path_factory.mktemp("logs")
    return run_sim_trial(spec, LUNG, STACK, log_dir=logs)


def test_the_relaxed_modulus_of_a_relaxing_lung_layer(relaxing: TrialOutcome) -> None:
    assert relaxing.state == "done", relaxing.reason
    fit = relaxing.relaxation
    assert fit is not None
    assert fit.success, fit.message
    assert fit.relaxes
    assert fit.complete
    assert fit.hypotheses == 4  # nu's range, fitted through, not the elastic fit's best
    assert fit.relaxed == pytest.approx(1.6e3, rel=0.08)
    assert fit.covers(1.6e3)
    assert fit.relaxation_time == pytest.approx(0.3, rel=0.3)


def test_the_relaxation_is_not_blamed_on_the_thickness(relaxing: TrialOutcome) -> None:
    assert relaxing.verdict is not None
    assert relaxing.relaxed_verdict is not None
    for verdict in (relaxing.verdict, relaxing.relaxed_verdict):
        assert not any(r.startswith(CONTRADICTED) for r in verdict.reasons), verdict
    assert any(r.startswith("relaxes in the hold") for r in relaxing.verdict.reasons)


def test_the_log_replays_to_the_same_relaxation(relaxing: TrialOutcome) -> None:
    assert relaxing.log_path is not None
    report = replay(Path(relaxing.log_path))
    assert report["identical"] is True, report


def test_a_relaxing_sample_answers_with_its_relaxed_modulus(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Two trials of N1 (1.2 kPa relaxed, a power law): the sample's one answer is the relaxed
    modulus, not the pooled elastic fit's apparent one, and no thickness is blamed."""
    from palpate.cli import main

    scene = str(resolve("scenes/lung/relaxing.yaml"))
    args = ["sim", "--scene", scene, "--limit", "2", "--no-plots", "--json"]
    assert main([*args, "--workers", "1", "--out", str(tmp_path)]) == 0
    (n1,) = json.loads(capsys.readouterr().out)["samples"]
    assert n1["pooled_modulus"] == "relaxed"
    assert n1["pooled_trials"] == 2
    assert n1["pooled_kpa"] == pytest.approx(1.2, rel=0.08)
    assert n1["pooled_interval_holds_truth"] is True
    assert "prefers" not in n1["pooled_reasons"]
