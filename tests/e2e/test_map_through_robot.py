"""A map through the robot (issue 58): the tissue stays, a positioner carries the robot, and
each probe is a robot trial placed square on to the patch's plane by the positioner's inverse
kinematics (``campaigns.throughrobot``), through the emulated bus and board as every trial."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest
from transforms3d.quaternions import quat2mat

from palpate.campaigns.mapstudy import run_map_study, summarise_study
from palpate.campaigns.survey import moved_scene, probe_spec, run_survey
from palpate.campaigns.throughrobot import ThroughRobot, map_surface
from palpate.cli import main
from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.maps import Probe
from palpate.maps.probes import normal_scores
from palpate.robot import kinematics
from palpate.robot.records.recording import read_recording
from palpate.simulation.trial import run_sim_trial

SCENE = resolve("scenes/maps/inclusion.yaml")


def through(scene: SceneConfig, tilt_deg: float = 30.0, **campaign: object) -> SceneConfig:
    return dataclasses.replace(
        scene,
        campaign=dataclasses.replace(
            scene.campaign, map_through="robot", map_tilt_deg=tilt_deg, **campaign
        ),
    )


def registered_wrong(scene: SceneConfig, tilt_deg: float) -> SceneConfig:
    """The sample turned ``tilt_deg`` off the plane the plan believes in, its tip sticking."""
    turned = tuple(
        dataclasses.replace(s, tilt_deg=tilt_deg, tilt_azimuth_deg=30.0, friction=1.0)
        for s in scene.samples
    )
    return dataclasses.replace(scene, samples=turned)


@pytest.fixture(scope="module")
def scene() -> SceneConfig:
    return load(SceneConfig, SCENE)


def test_the_tube_of_the_plane_s_tilt_meets_each_point_square_on(scene: SceneConfig) -> None:
    tilted = through(scene, 30.0)
    stack = load_stack(resolve(scene.robot))
    reach = ThroughRobot.of(tilted, stack)
    plane = map_surface(tilted, stack)
    centre = reach.place((0.0, 0.0))
    assert (centre.tube, centre.status) == ("bent30", 0)
    assert np.allclose(centre.base, 0.0, atol=1e-9)  # the plane's origin is at stage zero
    aside = reach.place((6e-3, -4e-3))
    assert aside.status == 0
    assert aside.residual < 1e-6
    assert np.linalg.norm(aside.base) == pytest.approx(math.hypot(6e-3, 4e-3), rel=1e-6)
    pose = kinematics.forward(stack.tube("bent30"), aside.roll, aside.contact_translation)
    target = plane.at(6e-3, -4e-3)
    r = stack.sensor.tip_radius
    assert np.allclose(pose.sensor_tip + aside.base, target.point + r * target.normal, atol=1e-9)


def test_a_probe_through_the_robot_reads_what_the_stage_s_probe_reads(scene: SceneConfig) -> None:
    stack = load_stack(resolve(scene.robot))
    tilted = through(scene, 30.0)
    reach = ThroughRobot.of(tilted, stack)
    sample = scene.campaign_samples()[0]
    point = (3e-3, -2e-3)  # over the sphere
    spec = probe_spec(scene, sample, 0, point, 0)
    bench = run_sim_trial(spec, moved_scene(scene, sample, point), stack)
    placed = reach.place(point)
    spec = reach.spec(spec, placed, point)
    assert spec.kind == "robot"
    assert spec.tube.name == "bent30"
    robot = run_sim_trial(spec, moved_scene(tilted, sample, point), stack)
    assert bench.joint is not None
    assert robot.joint is not None
    assert robot.joint.modulus == pytest.approx(bench.joint.modulus, rel=0.03)
    assert robot.true_misalignment is not None
    assert robot.true_misalignment < math.radians(0.01)


def test_a_plane_registered_wrong_is_caught_by_probing_or_said(scene: SceneConfig) -> None:
    stack = load_stack(resolve(scene.robot))
    wrong = registered_wrong(through(scene, 30.0), 4.0)
    blind = run_survey(wrong, stack, strategy="raster", max_probes=4)
    errors = [math.degrees(p.normal_error or 0.0) for p in blind.probes]
    assert errors == pytest.approx([4.0] * 4, abs=1e-6)  # the truth, which nobody measured
    assert normal_scores(blind.probes)["off_normal_unflagged"] == 4  # the score sees it
    probing = through(wrong, 30.0, probe=True)
    felt = run_survey(probing, stack, strategy="raster", max_probes=4)
    scores = normal_scores(felt.probes)
    assert scores["off_normal_unflagged"] == 0
    for p in felt.probes:  # re-rolled toward the measured normal, or a verdict that says not
        assert (p.normal_error or 0.0) < math.radians(4.0)


def test_a_point_the_stage_cannot_reach_is_a_probe_that_says_why(scene: SceneConfig) -> None:
    stack = load_stack(resolve(scene.robot))
    short = through(scene, 30.0, positioner_travel_mm=2.0)
    result = run_survey(short, stack, strategy="raster", max_probes=4)
    far = [k for k, p in enumerate(result.probes) if math.hypot(p.x, p.y) > 2.5e-3]
    assert far
    for k in far:
        p = result.probes[k]
        assert p.modulus is None
        assert p.status == "none"
        assert p.reasons == ("not reached: the stage's travel does not reach the base this needs",)
        assert result.outcomes[k] is None  # no trial ran


def test_a_plane_no_tube_meets_square_on_is_probed_obliquely_and_said(
    scene: SceneConfig,
) -> None:
    stack = load_stack(resolve(scene.robot))
    result = run_survey(through(scene, 40.0), stack, strategy="raster", max_probes=1)
    (p,) = result.probes
    assert p.normal_error == pytest.approx(math.radians(10.0), abs=math.radians(0.01))
    assert p.status in ("suspect", "none")
    assert any(r.startswith("oblique: 10.0 deg") for r in p.reasons)


def test_a_probe_s_normal_error_is_written_and_read_back_and_absent_without_one() -> None:
    p = Probe(1e-3, 2e-3, 3e5, (2.9e5, 3.1e5), "ok", (), 4.0, 1e-3, math.radians(1.5))
    assert Probe.from_record(json.loads(json.dumps(p.record()))) == p
    assert p.as_dict()["normal_error_deg"] == pytest.approx(1.5)
    level = dataclasses.replace(p, normal_error=None)
    assert "normal_error_rad" not in level.record()
    assert "normal_error_deg" not in level.as_dict()
    assert normal_scores([level]) == {}


def test_a_trial_facing_its_tube_logs_its_spec_as_before(scene: SceneConfig) -> None:
    sample = scene.campaign_samples()[0]
    spec = probe_spec(scene, sample, 0, (0.0, 0.0), 0)
    assert "facing" not in spec.record()
    turned = dataclasses.replace(spec, facing=(-1.0, 0.0, 0.0))
    assert turned.record()["facing"] == (-1.0, 0.0, 0.0)


def test_the_report_says_how_square_on_the_probes_pressed(scene: SceneConfig) -> None:
    from palpate.reports.mapresults import map_lines

    stack = load_stack(resolve(scene.robot))
    wrong = registered_wrong(through(scene, 30.0), 3.0)
    result = run_survey(wrong, stack, strategy="raster", max_probes=4)
    text = "\n".join(map_lines(result, Path("run"), "t", "raster"))
    assert "every probe's axis within 3.0 deg of the true surface normal" in text
    assert "4 beyond 2 deg, 4 of them without a verdict that says so" in text


def test_palpate_map_through_the_robot_writes_each_probe_s_normal_error_and_a_3d_figure(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["map", "--through", "robot", "--tilt-deg", "15", "--max-probes", "4"]
    assert main([*argv, "--strategy", "raster", "--out", str(tmp_path), "--json"]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["scores"]["normal_error_max_deg"] == pytest.approx(0.0, abs=1e-6)
    assert Path(payload["figure_3d"]).stat().st_size > 10_000  # the robot and the patch drawn
    (run,) = tmp_path.iterdir()
    probes = json.loads((run / "map.json").read_text(encoding="utf-8"))["probes"]
    assert [p["normal_error_deg"] for p in probes] == pytest.approx([0.0] * 4, abs=1e-6)
    rec = read_recording(run / "map.mcap")  # where the tissue and the robot stood, as /tf
    assert rec.count("/tf") == 4
    _, last = rec.messages["/tf"][-1]
    frames = {(t.header.frame_id, t.child_frame_id): t.transform for t in last.transforms}
    sample, base = frames[("world", "sample")], frames[("world", "base")]
    q = sample.rotation
    rotation = quat2mat((q.w, q.x, q.y, q.z))
    origin = np.array([sample.translation.x, sample.translation.y, sample.translation.z])
    at = origin + rotation @ np.array([probes[-1]["x_mm"], probes[-1]["y_mm"], 0.0]) * 1e-3
    stack = load_stack(resolve("robot.yaml"))
    reach = ThroughRobot.of(through(load(SceneConfig, SCENE), 15.0), stack)
    assert at == pytest.approx(
        reach.surface.at(probes[-1]["x_mm"] * 1e-3, probes[-1]["y_mm"] * 1e-3).point, abs=1e-9
    )
    moved = np.array([base.translation.x, base.translation.y, base.translation.z])
    assert np.linalg.norm(moved) > 1e-3  # the positioner carried the robot off stage zero


@pytest.mark.parametrize(
    ("argv", "named"),
    [
        (["--tilt-deg", "20"], "campaign.map_tilt_deg"),
        (["--through", "stage,robot"], "--worlds"),
        (["--through", "robot", "--tilt-deg", "95"], "--tilt-deg"),
    ],
)
def test_palpate_map_refuses_what_the_stage_cannot_do(
    argv: list[str], named: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["map", *argv, "--out", str(tmp_path)]) == 2
    assert named in capsys.readouterr().err


def test_a_study_surveys_the_same_worlds_both_ways_side_by_side(scene: SceneConfig) -> None:
    stack = load_stack(resolve(scene.robot))
    rows = run_map_study(scene, stack, worlds=1, plans=[("raster", 4)], throughs=("stage", "robot"))
    ways = sorted((r["through"], r["plain"]) for r in rows)
    assert ways == [("robot", False), ("stage", False)]
    by_way = {r["through"]: r for r in rows}
    moduli = [[p["modulus_pa"] for p in by_way[w]["probe_list"]] for w in ("stage", "robot")]
    assert moduli[1] == pytest.approx(moduli[0], rel=0.03)  # the same world, either way
    lines = summarise_study(rows)
    assert [line.get("through") for line in lines] == [None, "robot"]
    assert lines[1]["normal_error_max_deg"] == pytest.approx(0.0, abs=1e-6)


@pytest.mark.parametrize(
    ("tilt_deg", "reasons", "kept"),
    [
        (3.0, ("misalignment 2.1 deg beyond the campaign's tolerance of 2 deg",), True),
        (6.0, ("misalignment 4.1 deg beyond the campaign's tolerance of 2 deg",), False),
        (None, ("misalignment 2.1 deg beyond the campaign's tolerance of 2 deg",), False),
        (3.0, ("misalignment 2.1 deg beyond ...", "imprecise: the 95 % interval spans"), False),
        (3.0, ("oblique: 10.0 deg from the surface normal",), False),
    ],
)
def test_a_probe_suspect_for_a_small_measured_tilt_alone_keeps_its_interval(
    tilt_deg: float | None, reasons: tuple[str, ...], kept: bool
) -> None:
    tilt = None if tilt_deg is None else math.radians(tilt_deg)
    ok = Probe(0.0, 0.0, 3e5, (2.9e5, 3.1e5), "ok")
    suspect = dataclasses.replace(ok, status="suspect", reasons=reasons, tilt=tilt)
    ratio = suspect.log_sigma() / ok.log_sigma()
    assert ratio == pytest.approx(1.0 if kept else 2.0)
    assert Probe.from_record(json.loads(json.dumps(suspect.record()))) == suspect


def test_a_probing_survey_says_how_far_each_trial_s_touches_allow_the_tilt(
    scene: SceneConfig,
) -> None:
    stack = load_stack(resolve(scene.robot))
    felt = run_survey(
        through(registered_wrong(scene, 3.0), 30.0, probe=True),
        stack,
        strategy="raster",
        max_probes=4,
    )
    for p in felt.probes:
        assert p.tilt is not None
        assert p.normal_error is not None
        assert p.tilt >= p.normal_error - math.radians(0.5)  # the touches' bound holds the truth


def test_a_probe_the_trial_could_not_turn_square_on_says_why_and_claims_no_normal(
    scene: SceneConfig,
) -> None:
    """Registered 4 deg wrong along the bent tube's bend, where no roll helps: the trial's
    touches find the normal, no roll meets it within the tolerance, and it ends unreachable."""
    stack = load_stack(resolve(scene.robot))
    wrong = through(registered_wrong(scene, 4.0), 30.0, probe=True)
    along = tuple(dataclasses.replace(s, tilt_azimuth_deg=90.0) for s in wrong.samples)
    wrong = dataclasses.replace(wrong, samples=along)
    result = run_survey(wrong, stack, strategy="raster", max_probes=1)
    (p,) = result.probes
    assert result.outcomes[0].state == "unreachable"
    assert p.modulus is None
    assert p.reasons[0].startswith("unreachable: no orthogonal pose of tube bent30")
    assert p.normal_error is None  # it never indented


def domed(scene: SceneConfig, radius_mm: float) -> SceneConfig:
    """The scene's samples curved into a convex dome facing the robot, their tips sticking."""
    curved = tuple(
        dataclasses.replace(s, curvature_radius_mm=radius_mm, friction=1.0) for s in scene.samples
    )
    return dataclasses.replace(scene, samples=curved)


def test_on_a_dome_the_normal_turns_and_the_tube_of_its_angle_meets_it_square_on(
    scene: SceneConfig,
) -> None:
    stack = load_stack(resolve(scene.robot))
    dome = through(domed(scene, 40.0), 0.0)
    reach = ThroughRobot.of(dome, stack)
    apex = reach.place((0.0, 0.0))
    assert (apex.tube, apex.status) == ("straight", 0)
    ring = 40e-3 * math.radians(15.0)  # where the normal has turned by the bent15's angle
    aside = reach.place((0.0, ring))
    assert (aside.tube, aside.status) == ("bent15", 0)
    assert aside.residual < 1e-6
    between = reach.place((0.0, 0.5 * ring))  # 7.5 deg: between the straight and the bent15
    assert between.status == 1
    assert math.degrees(between.residual) == pytest.approx(7.5, abs=0.01)
    spec = reach.spec(probe_spec(dome, dome.samples[0], 0, (0.0, ring), 0), aside, (0.0, ring))
    n = reach.surface.at(0.0, ring).normal
    assert spec.facing == pytest.approx(tuple(n))


def test_a_dome_survey_presses_where_placed_and_says_which_probes_were_off_the_normal(
    scene: SceneConfig,
) -> None:
    stack = load_stack(resolve(scene.robot))
    dome = through(domed(scene, 40.0), 0.0, probe="measure")
    result = run_survey(dome, stack, strategy="raster", max_probes=4)
    assert all(p.modulus is not None for p in result.probes)  # every one indented
    errors = [p.normal_error for p in result.probes]
    assert all(e is not None for e in errors)
    assert max(e or 0.0 for e in errors) > math.radians(2.0)  # between the tubes' cones
    assert normal_scores(result.probes)["off_normal_unflagged"] == 0
