"""A trial the heart buckles unread runs again at a shorter exposed length (issue 62,
``campaign.retry_lengths_mm``): beside a 0.5 mm beat, in a breath hold that drifts 1.5 mm (0.1
mm/s, as fast as the stage), a 20 kPa sample buckles the 45 mm beam within one quiet window of
the heart and gives no estimate; at 30 mm the beam's critical load is 2.25 times higher, the
quiet windows in contact are more and the record reads it. Both attempts keep their logs, the
row names the attempt that stands and the one before it, and ``--resume`` follows the same
chain."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml

from palpate.campaigns.shorter import at_length, buckled_unread, retries
from palpate.cli import main
from palpate.config import load, resolve
from palpate.config.scene import SceneConfig

NEAR_HEART = resolve("scenes/invivo/near-heart.yaml")


def scene_file(tmp_path: Path, **campaign: object) -> Path:
    """near-heart's scene, a hold drifting 1.5 mm, one trial of F4 (20 kPa) on the 30 deg
    tube, with ``campaign``."""
    raw = yaml.safe_load(NEAR_HEART.read_text(encoding="utf-8"))
    raw["robot"] = str(resolve(raw["robot"]))
    raw["fidelity"]["breathing"]["residual_mm"] = 1.5
    raw["campaign"].update(samples=["F4"], tubes=["bent30"], orientations=["downward"])
    raw["campaign"].update(campaign)
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(raw), encoding="utf-8")
    return path


def test_a_retry_is_named_for_its_length_and_only_shorter_ones_run(tmp_path: Path) -> None:
    from palpate.campaigns.campaign import campaign_trials
    from palpate.config import load_stack

    scene = load(SceneConfig, scene_file(tmp_path, retry_lengths_mm=[30, 40]))
    (spec,) = campaign_trials(scene, load_stack(scene.robot))
    assert spec.trial_id == "F4-bent30-downward-L45"
    again = retries(spec, scene.campaign)
    assert [s.trial_id for s in again] == ["F4-bent30-downward-L40", "F4-bent30-downward-L30"]
    assert [s.exposed_length for s in again] == pytest.approx([0.040, 0.030])
    assert again[-1].seed == spec.seed
    assert again[-1].sample == spec.sample
    assert retries(again[-1], scene.campaign) == []  # nothing shorter than the shortest
    assert at_length(spec, 0.030).trial_id.endswith("-L30")


@pytest.mark.parametrize(
    ("lengths", "says"),
    [([50], "no shorter than the trials' 45 mm"), ([20], "leaves a grating inside the tube")],
)
def test_a_retry_length_that_cannot_run_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], lengths: list[float], says: str
) -> None:
    path = scene_file(tmp_path, retry_lengths_mm=lengths)
    assert main(["sim", "--scene", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert str(path) in err
    assert "campaign.retry_lengths_mm[0]" in err
    assert says in err
    assert not (tmp_path / "out").exists()  # refused before anything ran


def sim(scene: Path, out: Path, capsys: pytest.CaptureFixture[str], *extra: str) -> dict:  # type: ignore[type-arg]
    code = main(["sim", "--scene", str(scene), "--out", str(out), "--no-plots", "--json", *extra])
    assert code == 0, capsys.readouterr().err
    return json.loads(capsys.readouterr().out)  # type: ignore[no-any-return]


@pytest.mark.slow  # three simulated lung trials beside the heart
def test_a_trial_the_heart_buckles_unread_reads_at_a_shorter_length(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = scene_file(tmp_path, retry_lengths_mm=[30])
    whole = sim(scene, tmp_path / "out", capsys)
    (row,) = whole["trials"]
    assert row["trial"] == "F4-bent30-downward-L30"
    assert row["tried"] == ["F4-bent30-downward-L45"]
    assert row["exposed_length_mm"] == pytest.approx(30.0)
    assert row["joint_kpa"] == pytest.approx(20.0, rel=0.2)
    lo, hi = row["joint_ci_kpa"]
    assert lo <= 20.0 <= hi
    logs = Path(whole["log_dir"])
    first = logs / "F4-bent30-downward-L45.jsonl"
    assert first.exists()
    assert (logs / "F4-bent30-downward-L30.jsonl").exists()
    assert buckled_unread_from(first, scene)  # the attempt at 45 mm, read back

    # resumed with the last attempt's log gone: the chain runs again to the same row
    (logs / "F4-bent30-downward-L30.jsonl").unlink()
    resumed = sim(scene, tmp_path / "out", capsys, "--resume")
    assert [dict(t, log=None) for t in resumed["trials"]] == [dict(row, log=None)]
    # resumed with every log in place: nothing runs, the same row
    kept = first.read_bytes()
    again = sim(scene, tmp_path / "out", capsys, "--resume")
    assert [dict(t, log=None) for t in again["trials"]] == [dict(row, log=None)]
    assert first.read_bytes() == kept
    # the report says it too
    args = ["sim", "--scene", str(scene), "--out", str(tmp_path / "out"), "--no-plots"]
    assert main([*args, "--resume"]) == 0
    assert "1 trials buckled without an estimate and ran again at a shorter exposed length" in (
        capsys.readouterr().out
    )


def buckled_unread_from(log: Path, scene: Path) -> bool:
    """The outcome that ``log`` stands for buckled and gave no estimate."""
    from palpate.campaigns.campaign import campaign_trials
    from palpate.campaigns.resume import outcome_from_log
    from palpate.config import load_stack

    config = load(SceneConfig, scene)
    stack = load_stack(config.robot)
    (spec,) = campaign_trials(config, stack)
    outcome = outcome_from_log(log, spec, stack)
    assert outcome is not None
    return buckled_unread(outcome)
