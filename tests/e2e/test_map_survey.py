"""A map survey through whole simulated trials: the servos on the emulated bus, the board's
frames, the state machine and the estimator at every probe, the world the 3-D inclusion factor
of the shipped map scene (issue 40)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from palpate.campaigns.survey import PROBES_FILE, moved_scene, read_probes, run_survey
from palpate.cli import main
from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.maps import Probe
from palpate.robot.records.recording import read_recording
from palpate.sim.fem3d.offsets import MapWorld
from palpate.sim.sample_law import fe_world

SCENE = resolve("scenes/maps/inclusion.yaml")


@pytest.fixture(scope="module")
def scene() -> SceneConfig:
    return load(SceneConfig, SCENE)


def test_a_probe_sees_the_inclusion_from_where_it_presses(scene: SceneConfig) -> None:
    stack = load_stack(resolve(scene.robot))
    sample = scene.campaign_samples()[0]
    tip = stack.sensor.tip_radius
    over = moved_scene(scene, sample, (3e-3, -2e-3)).samples[0]
    away = moved_scene(scene, sample, (-7e-3, 8e-3)).samples[0]
    w_over, w_away = (fe_world(s, scene.fidelity, tip) for s in (over, away))
    assert isinstance(w_over, MapWorld)
    assert isinstance(w_away, MapWorld)
    assert w_over.offset == 0.0
    assert w_away.offset == pytest.approx(((10e-3) ** 2 + (10e-3) ** 2) ** 0.5 / tip, rel=1e-6)
    f_over, f_away = (w.table().forces[-1] for w in (w_over, w_away))
    assert f_over > 1.2 * f_away  # over the sphere the layer is stiffer


def test_a_killed_survey_resumes_from_its_probes_file(scene: SceneConfig, tmp_path: Path) -> None:
    stack = load_stack(resolve(scene.robot))
    taken: list[Probe] = []

    def kill_after_two(p: Probe) -> None:
        taken.append(p)
        if len(taken) == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_survey(
            scene, stack, strategy="raster", max_probes=4, run_dir=tmp_path, on_probe=kill_after_two
        )
    assert len(read_probes(tmp_path / PROBES_FILE)) == 2
    again = run_survey(scene, stack, strategy="raster", max_probes=4, run_dir=tmp_path)
    assert again.probes[:2] == taken  # read back as written
    assert len(read_probes(tmp_path / PROBES_FILE)) == 4
    assert len(again.outcomes) == 2
    assert len(list((tmp_path / "logs").glob("p*.jsonl"))) == 4  # every probe a logged trial
    assert all(p.lab_time > 0 for p in again.probes)
    assert again.summary is not None  # four probes with numbers make a map


@pytest.mark.slow
def test_palpate_map_prints_the_map_and_writes_its_run_folder(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(
        ["map", "--strategy", "raster", "--max-probes", "4", "--json", "--out", str(tmp_path)]
    )
    assert code == 0
    payload = json.loads(capsys.readouterr().out)
    for key in ("probes_used", "inclusion_found", "inclusion_center_mm", "inclusion_radius_mm",
                "lab_time_s", "truth", "scores"):  # fmt: skip
        assert key in payload, key
    assert payload["probes_used"] == 4
    assert payload["truth"]["contrast"] == pytest.approx(5.0)
    assert "apparent_radius_mm" in payload
    assert "extent" in payload  # None here: four probes cannot carry the disc's fit
    # each probe carries how wide its tip read the tissue: sqrt(R delta), R = 3.5 mm
    radii = [p["contact_radius_mm"] for p in payload["probes"] if p["modulus_kpa"] is not None]
    assert radii
    assert all(1.0 < a < 3.5 for a in radii), radii
    run_dir = Path(payload["run_dir"])
    assert (run_dir / "map.png").stat().st_size > 0
    assert json.loads((run_dir / "map.json").read_text())["probes_used"] == 4
    rec = read_recording(run_dir / "map.mcap")  # the map after each probe, as ROS 2 messages
    assert rec.complete
    assert rec.types["/map/grid"] == "sensor_msgs/msg/PointCloud2"
    assert rec.count("/map/probes") == 4
    assert rec.count("/map/grid") == 2  # from the third usable probe on
    _, grid = rec.messages["/map/grid"][-1]
    assert [f.name for f in grid.fields] == ["x", "y", "z", "modulus_kpa", "sd", "p_above"]
    values = np.frombuffer(bytes(grid.data), "<f8").reshape(grid.width, 6)
    assert np.all((values[:, 5] >= 0) & (values[:, 5] <= 1))
    assert np.all(values[:, 3] > 100)  # kPa: the phantom's hundreds


def test_palpate_map_refuses_a_scene_that_is_not_a_map(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["map", "--scene", str(resolve("scenes/bench.yaml")), "--out", str(tmp_path)]) == 2
    assert "campaign.kind" in capsys.readouterr().err
    assert main(["map", "--sample", "nobody", "--out", str(tmp_path)]) == 2
    assert main(["map", "--worlds", "1", "--plans", "spiral:3", "--out", str(tmp_path)]) == 2
    assert "--plans" in capsys.readouterr().err
    assert main(["map", "--worlds", "1", "--whole", "--out", str(tmp_path)]) == 2
    assert "inclusion_offsets: patch" in capsys.readouterr().err


def test_a_map_scene_with_a_bad_key_is_refused(tmp_path: Path) -> None:
    bad = tmp_path / "m.yaml"
    text = SCENE.read_text(encoding="utf-8").replace("max_probes: 30", "max_probes: 0")
    bad.write_text(text, encoding="utf-8")
    assert main(["map", "--scene", str(bad), "--out", str(tmp_path)]) == 2


def test_a_study_places_each_world_s_inclusion_inside_the_patch(scene: SceneConfig) -> None:
    from palpate.campaigns.mapstudy import world_scene

    x0, y0, x1, y1 = scene.campaign.patch_mm
    centres = []
    for k in range(20):
        (inc,) = world_scene(scene, k, seed=3).samples[0].inclusions
        cx, cy, depth = inc.center_mm
        assert x0 + inc.radius_mm <= cx <= x1 - inc.radius_mm
        assert y0 + inc.radius_mm <= cy <= y1 - inc.radius_mm
        assert depth == scene.campaign_samples()[0].inclusions[0].center_mm[2]
        centres.append((cx, cy))
    assert len(set(centres)) == 20  # seeded apart
    assert world_scene(scene, 4, seed=3) == world_scene(scene, 4, seed=3)
    assert world_scene(scene, 4, seed=3, plain=True).samples[0].inclusions == ()


@pytest.mark.slow
def test_a_study_scores_every_survey_against_its_world(scene: SceneConfig) -> None:
    from palpate.campaigns.mapstudy import run_map_study, summarise_study, wilson

    stack = load_stack(resolve(scene.robot))
    rows = run_map_study(scene, stack, worlds=1, plans=[("raster", 4)], seed=0, workers=1)
    (row,) = rows
    assert row["probes"] == 4
    assert len(row["probe_list"]) == 4
    assert "boundary_error_mm2" in row
    (line,) = summarise_study(rows)
    assert line["worlds"] == 1
    assert line["detected"] == int(row["found"])
    lo, hi = wilson(12, 12)
    assert 0.7 < lo < 0.8
    assert hi == 1.0
