"""A lung trial beside the heart (issue 62): the world beats the surface 0.5 mm along the axis at
70 a minute and an ECG's R waves reach the board (frame status bit 7); the trial indents slowly
once it sees them, the estimate takes the beat out of the record (its amplitude measured, not
told), the verdict names it, and a replay of the log gives the same estimate. Without a heart
nothing of it runs. Beside a stiff sample the record is read in the heart's quiet phase."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest

from palpate.campaigns.campaign import campaign_trials
from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.reports.replay import replay
from palpate.robot.records.log import read_log
from palpate.simulation.result import TrialOutcome
from palpate.simulation.trial import run_sim_trial

pytestmark = pytest.mark.slow  # two simulated lung trials

SCENE = load(SceneConfig, resolve("scenes/invivo/near-heart.yaml"))
STACK = load_stack(SCENE.robot)


def run_n2(
    scene: SceneConfig, tmp_path_factory: pytest.TempPathFactory, sample: str = "N2"
) -> TrialOutcome:
    """N2 (2 kPa, 40 mm; or ``sample``) through the 15 deg tube, downward."""
    spec = next(
        s
        for s in campaign_trials(scene, STACK, 0)
        if s.sample == sample and s.tube.name == "bent15" and s.orientation == "downward"
    )
    return run_sim_trial(spec, scene, STACK, log_dir=tmp_path_factory.mktemp("logs"))


@pytest.fixture(scope="module")
def beating(tmp_path_factory: pytest.TempPathFactory) -> TrialOutcome:
    return run_n2(SCENE, tmp_path_factory)


def test_the_beat_is_measured_and_taken_out(beating: TrialOutcome) -> None:
    assert beating.state == "done", beating.reason
    assert beating.heart == pytest.approx(0.5e-3, rel=0.1)  # peak to peak, measured
    assert beating.joint is not None
    assert beating.joint.modulus is not None
    assert beating.joint.modulus == pytest.approx(2e3, rel=0.1)
    assert beating.joint.ci_low is not None
    assert beating.joint.ci_high is not None
    assert beating.joint.ci_low <= 2e3 <= beating.joint.ci_high
    assert beating.verdict is not None
    assert any(r.startswith("heartbeat: the surface beat") for r in beating.verdict.reasons)


def test_the_log_keeps_the_r_waves_and_replays_the_estimate(beating: TrialOutcome) -> None:
    assert beating.log_path is not None
    samples = list(read_log(beating.log_path).of_kind("sample"))
    indenting = [r for r in samples if r["state"] == "indenting"]
    first, last = indenting[0], indenting[-1]
    speed = (last["advance"] - first["advance"]) / (last["t"] - first["t"])
    assert speed == pytest.approx(0.1e-3, rel=0.1)  # the heart's 0.1 mm/s, not the scene's 0.5
    assert sum(1 for r in samples if r.get("beat")) > 20
    assert replay(beating.log_path)["identical"] is True


def test_without_a_heart_nothing_of_it_runs(tmp_path_factory: pytest.TempPathFactory) -> None:
    fidelity = SCENE.fidelity
    assert fidelity.breathing is not None
    still = dataclasses.replace(fidelity.breathing, cardiac_mm=0.0)
    scene = dataclasses.replace(SCENE, fidelity=dataclasses.replace(fidelity, breathing=still))
    outcome = run_n2(scene, tmp_path_factory)
    assert outcome.state == "done", outcome.reason
    assert outcome.heart is None
    assert outcome.log_path is not None
    assert not any(r.get("beat") for r in read_log(outcome.log_path).of_kind("sample"))
    assert outcome.verdict is not None
    assert not any(r.startswith("heartbeat") for r in outcome.verdict.reasons)


def arrived_in_a_hold(log: str | Path, out: Path, *, gated: bool | None) -> Path:
    """``log`` as a trial that arrived in a breath hold writes it (no waiting rows), its
    estimator told ``gated`` (None: a log that predates it)."""
    header, *records = (json.loads(line) for line in Path(log).read_text().splitlines())
    header["estimator"].pop("gated", None)
    if gated is not None:
        header["estimator"]["gated"] = gated
    kept = [r for r in records if not (r["kind"] == "sample" and r["state"] == "waiting")]
    out.write_text("".join(json.dumps(r) + "\n" for r in [header, *kept]))
    return out


def test_a_gated_trial_that_arrives_in_a_hold_takes_the_beat_out(
    beating: TrialOutcome, tmp_path: Path
) -> None:
    assert beating.log_path is not None
    told = replay(arrived_in_a_hold(beating.log_path, tmp_path / "told.jsonl", gated=True))
    assert told["joint"]["modulus"] == pytest.approx(beating.joint.modulus, rel=0.05)  # type: ignore[union-attr]
    assert told["joint"]["modulus"] == pytest.approx(2e3, rel=0.1)
    older = replay(arrived_in_a_hold(beating.log_path, tmp_path / "older.jsonl", gated=None))
    assert abs(older["joint"]["modulus"] / 2e3 - 1) > 0.2  # the beat left in: a wrong read


def test_a_stiff_sample_the_systole_buckles_reads_in_the_quiet_phase(
    tmp_path_factory: pytest.TempPathFactory,
) -> None:
    """F4 (20 kPa): the systole buckles the 45 mm beam long before the stage presses the still
    tissue (the fourth round's estimator gave none here, even at 30 mm). The machine goes on to
    buckling in mid-diastole, stands there through two quiet windows, and the record read in
    the quiet phase holds the truth; the breath hold's drift is read from it."""
    outcome = run_n2(SCENE, tmp_path_factory, "F4")
    assert outcome.state == "done", outcome.reason
    assert outcome.joint is not None
    assert outcome.joint.success, outcome.joint.message
    assert outcome.joint.ci_low is not None
    assert outcome.joint.ci_high is not None
    assert outcome.joint.ci_low <= 20e3 <= outcome.joint.ci_high
    assert outcome.joint.modulus == pytest.approx(20e3, rel=0.25)
    assert outcome.motion is not None
    assert outcome.motion > 0
    assert outcome.log_path is not None
    rows = [r for r in read_log(outcome.log_path).of_kind("sample") if r["state"] == "buckled"]
    assert max(r["advance"] for r in rows) - min(r["advance"] for r in rows) < 10e-6  # it stood
    assert rows[-1]["t"] - rows[0]["t"] > SCENE.fidelity.breathing.cardiac_period_s  # type: ignore[union-attr]
