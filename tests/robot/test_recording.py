"""MCAP recordings beside the trial log (``robot.records.recording``), read back without ROS:
every channel typed with its ROS 2 definition, a message per log record, times that never
decrease, the export of an existing log, and the tip force from the estimator's beam states."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from palpate.cli import main
from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.estimation.trial.inputs import header_sensor
from palpate.estimation.trial.states import record_states
from palpate.robot.records.export import export
from palpate.robot.records.log import TrialLog, read_log
from palpate.robot.records.recording import Recording, read_recording
from palpate.robot.trial.tipforce import axial_loads
from palpate.simulation.trial import TrialOutcome, TrialSpec, run_sim_trial
from palpate.simulation.world import BENCH_COLUMN

STACK = load_stack()
BENCH = load(SceneConfig, resolve("scenes/bench.yaml"))
# the standard ROS 2 definitions (sensor_msgs, geometry_msgs), field by field
JOINT_STATE = ["std_msgs/Header header", "string[] name", "float64[] position",
               "float64[] velocity", "float64[] effort"]  # fmt: skip
WRENCH_STAMPED = ["std_msgs/Header header", "geometry_msgs/Wrench wrench"]


@pytest.fixture(scope="module")
def trial(tmp_path_factory: pytest.TempPathFactory) -> tuple[TrialOutcome, TrialLog, Recording]:
    logs = tmp_path_factory.mktemp("logs")
    spec = TrialSpec(
        "S8-L44", "bench", "S8", 314.53e3, 0.45, BENCH_COLUMN, "downward", 0.0, 44e-3, 3
    )
    out = run_sim_trial(spec, BENCH, STACK, log_dir=logs)
    path = Path(str(out.log_path))
    return out, read_log(path), read_recording(path.with_suffix(".mcap"))


def first_fields(definition: str) -> list[str]:
    return [
        x
        for x in definition.split("\n" + "=" * 80, maxsplit=1)[0].splitlines()
        if x and x[0] != "#"
    ]


def test_every_channel_has_its_schema_and_a_message_per_record(trial) -> None:  # type: ignore[no-untyped-def]
    _, log, rec = trial
    assert rec.complete
    samples = list(log.of_kind("sample"))
    assert rec.types["/joint_states"] == "sensor_msgs/msg/JointState"
    assert rec.types["/tip/wrench"] == "geometry_msgs/msg/WrenchStamped"
    assert first_fields(rec.schemas["sensor_msgs/msg/JointState"]) == JOINT_STATE
    assert first_fields(rec.schemas["geometry_msgs/msg/WrenchStamped"]) == WRENCH_STAMPED
    assert rec.count("/joint_states") == rec.count("/fbg/strains") == len(samples)
    assert rec.count("/tip/wrench") == len(samples)
    assert rec.count("/palpate/transition") == len(list(log.of_kind("transition")))
    others = [r for r in log.records if r["kind"] not in ("sample", "transition")]
    assert rec.count("/palpate/record") == len(others)
    header = {k: json.loads(v) for k, v in rec.metadata["palpate.trial"].items()}
    assert header == {k: v for k, v in log.header.items() if k != "kind"}
    for topic, msgs in rec.messages.items():
        times = [t for t, _ in msgs]
        assert times == sorted(times), topic


def test_each_message_type_round_trips_its_record(trial) -> None:  # type: ignore[no-untyped-def]
    _, log, rec = trial
    samples = list(log.of_kind("sample"))
    for sample, (t, joints), (_, fbg) in zip(
        samples, rec.messages["/joint_states"], rec.messages["/fbg/strains"], strict=True
    ):
        assert t == round(sample["t"] * 1e9)
        assert joints.header.stamp.sec * 10**9 + joints.header.stamp.nanosec == t
        assert list(joints.name) == ["stage_translation", "outer_roll"]
        assert list(joints.position) == [sample["advance"], sample["roll"]]
        assert list(fbg.strain) == sample["strains"]
        assert (fbg.state, fbg.contact) == (sample["state"], sample["contact"])
    for tr, (_, msg) in zip(
        log.of_kind("transition"), rec.messages["/palpate/transition"], strict=True
    ):
        assert (msg.from_state, msg.to_state, msg.reason) == (tr["from"], tr["to"], tr["reason"])
    others = [r for r in log.records if r["kind"] not in ("sample", "transition")]
    for record, (_, msg) in zip(others, rec.messages["/palpate/record"], strict=True):
        assert msg.kind == record["kind"]
        assert json.loads(msg.json) == record


def test_the_tip_force_is_the_estimators_axial_load(trial) -> None:  # type: ignore[no-untyped-def]
    _, log, rec = trial
    sensor, section, inputs = header_sensor(log.header)
    samples = list(log.of_kind("sample"))
    whole = np.array([len(s["strains"]) == len(sensor.used_gratings) for s in samples])
    advance = np.array([s["advance"] for s, w in zip(samples, whole, strict=True) if w])
    strains = np.array([s["strains"] for s, w in zip(samples, whole, strict=True) if w])
    states, _ = record_states(advance, strains, inputs, sensor, section)
    force = np.array([m.wrench.force.z for _, m in rec.messages["/tip/wrench"]])
    np.testing.assert_allclose(force[whole], -states.P, rtol=1e-12, atol=1e-12)
    assert np.all(np.isnan(force[~whole]))  # a tick without every grating has no force
    assert force[whole].min() < -0.5  # the sensor buckled: P_cr is about 1.4 N


def test_an_existing_log_exports_to_the_same_recording(trial, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    out, _, rec = trial
    target = export(Path(str(out.log_path)), tmp_path / "again.mcap", axial_loads)
    again = read_recording(target)
    assert again.types == rec.types
    assert {t: again.count(t) for t in again.messages} == {t: rec.count(t) for t in rec.messages}
    assert again.messages["/joint_states"][-1][0] == rec.messages["/joint_states"][-1][0]
    copy = tmp_path / "old.jsonl"
    copy.write_text(Path(str(out.log_path)).read_text(encoding="utf-8"), encoding="utf-8")
    assert main(["export", str(copy)]) == 0
    assert read_recording(copy.with_suffix(".mcap")).complete


def test_export_names_a_file_that_is_not_a_trial_log(tmp_path: Path) -> None:
    bad = tmp_path / "bad.jsonl"
    bad.write_text("not json\n", encoding="utf-8")
    assert main(["export", str(bad)]) == 2
    assert not bad.with_suffix(".mcap").exists()


def test_the_fast_encoders_are_byte_for_byte_the_definitions() -> None:
    """robot.records.cdr's packed messages equal mcap-ros2-support's definition-driven encoding."""
    from mcap_ros2._dynamic import serialize_dynamic

    from palpate.robot.records import cdr
    from palpate.robot.records.ros2 import SCHEMAS

    def encode(name: str, message: dict[str, object]) -> bytes:
        return bytes(serialize_dynamic(name, SCHEMAS[name])[name](message))

    stamp = {"sec": 12, "nanosec": 345}
    for frame, state, strain in (("", "a", []), ("sensor", "indenting", [1e-4, -2e-4, 3.5e-4])):
        head = {"stamp": stamp, "frame_id": frame}
        assert cdr.grating_strains(12 * 10**9 + 345, frame, state, strain, True, 0.0123) == encode(
            "palpate_msgs/msg/GratingStrains",
            {"header": head, "state": state, "strain": strain, "contact": True, "goal": 0.0123},
        )
        names = ["stage_translation", "outer_roll"]
        assert cdr.joint_state(12 * 10**9 + 345, frame, names, [0.01, -0.2]) == encode(
            "sensor_msgs/msg/JointState",
            {"header": head, "name": names, "position": [0.01, -0.2], "velocity": [], "effort": []},
        )
        force, torque = {"x": 0.5, "y": -1.0, "z": 2.0}, {"x": 0.0, "y": 0.25, "z": 0.0}
        assert cdr.wrench_stamped(12 * 10**9 + 345, frame, (0.5, -1.0, 2.0), (0.0, 0.25, 0.0)) == (
            encode(
                "geometry_msgs/msg/WrenchStamped",
                {"header": head, "wrench": {"force": force, "torque": torque}},
            )
        )


def test_a_robot_trial_records_the_tip_pose_as_the_forward_kinematics(tmp_path: Path) -> None:
    from transforms3d.quaternions import quat2mat

    from palpate.config.scene import SceneConfig as Scene
    from palpate.robot.kinematics import forward

    robot = load(Scene, resolve("scenes/robot.yaml"))
    spec = TrialSpec(
        "S8-bent30", "robot", "S8", 314.53e3, 0.45, STACK.tube("bent30"), "downward", 0.0, 42e-3, 2
    )
    out = run_sim_trial(spec, robot, STACK, log_dir=tmp_path)
    path = Path(str(out.log_path))
    rec, log = read_recording(path.with_suffix(".mcap")), read_log(path)
    samples = list(log.of_kind("sample"))
    assert rec.types["/tf"] == "tf2_msgs/msg/TFMessage"
    assert rec.count("/tf") == len(samples)
    tube = STACK.tube("bent30")
    for sample, (t, msg) in list(zip(samples, rec.messages["/tf"], strict=True))[::97]:
        pose = forward(tube, sample["roll"], sample["advance"])
        to_tip, to_sensor = msg.transforms
        assert (to_tip.header.frame_id, to_tip.child_frame_id) == ("base", "tube_tip")
        move = to_tip.transform.translation
        np.testing.assert_allclose([move.x, move.y, move.z], pose.tube_tip, atol=1e-12)
        q = to_tip.transform.rotation
        np.testing.assert_allclose(quat2mat([q.w, q.x, q.y, q.z]), pose.rotation, atol=1e-12)
        assert to_sensor.transform.translation.x == pytest.approx(pose.exposed_length, abs=1e-12)
        assert t == round(sample["t"] * 1e9)


def test_the_transform_encoder_is_byte_for_byte_the_definition() -> None:
    from mcap_ros2._dynamic import serialize_dynamic

    from palpate.robot.records import cdr
    from palpate.robot.records.ros2 import SCHEMAS

    name = "tf2_msgs/msg/TFMessage"
    encode = serialize_dynamic(name, SCHEMAS[name])[name]
    stamp = {"sec": 1, "nanosec": 2}
    transforms = [("base", "tube_tip", (1.0, 2.0, 3.0), (0.1, 0.2, 0.3, 0.9)),
                  ("tube_tip", "sensor_tip", (0.04, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))]  # fmt: skip
    message = {
        "transforms": [
            {
                "header": {"stamp": stamp, "frame_id": parent},
                "child_frame_id": child,
                "transform": {
                    "translation": dict(zip("xyz", xyz, strict=True)),
                    "rotation": dict(zip("xyzw", q, strict=True)),
                },
            }
            for parent, child, xyz, q in transforms
        ]
    }
    assert cdr.tf_message(10**9 + 2, transforms) == bytes(encode(message))


@pytest.mark.parametrize(("flags", "recorded"), [([], True), (["--no-mcap"], False)])
def test_palpate_sim_records_each_trial_unless_told_not_to(
    flags: list[str], recorded: bool, tmp_path: Path
) -> None:
    argv = ["sim", "--campaign", "bench", "--limit", "1", "--workers", "1", "--no-plots"]
    assert main([*argv, "--out", str(tmp_path), *flags]) == 0
    logs = list(tmp_path.rglob("*.jsonl"))
    assert len(logs) == 1
    assert logs[0].with_suffix(".mcap").exists() is recorded
