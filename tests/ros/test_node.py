"""The ROS 2 node (``palpate ros``) with real rclpy and DDS, each side in its own process as a
lab's software would be: a client (tests/ros/client.py) receives every topic during a simulated
trial, a trial run over ROS 2 gives the row ``palpate sim`` gives with the same seed, a stop
retracts the running trial, a survey publishes its map, and the names the node advertises are
the ones docs/ros2.md lists. Every test's DDS domain is its own, on the loopback."""

from __future__ import annotations

import contextlib
import itertools
import json
import os
import random
import re
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("rclpy", reason="the ros extra (ROS 2 wheels) is not installed")

from palpate.api import load_scene, read_log, read_recording, simulate_trial
from palpate.ros.jog import COMMAND_TIMEOUT_S
from palpate.ros.names import PARAMETERS, SERVICES, SUBSCRIPTIONS, TOPICS

# under pytest -n, one worker runs these in turn (two nodes at once could draw one DDS domain),
# each with no other worker's test beside it: a jog's servo_jp once went unanswered for 600 s
# beside one ("a trial or survey holds the robot", docs/speed.md), where alone they pass
pytestmark = [pytest.mark.xdist_group("ros"), pytest.mark.alone]
CLIENT = Path(__file__).with_name("client.py")
STILL_S = 1.0  # s of the node's clock the client waits for the robot to stand still (client.py)
DOCS = Path(__file__).resolve().parents[2] / "docs" / "ros2.md"
WAIT_S = 600.0  # a bound on waiting for a process (a busy machine), never a measured time
LATENCY_S = 1.0  # wall s a jog's commands and joint states may take between node and client
PACE = 0.2  # trial seconds per wall second for the tests that stop a trial under way: its
# 4 s last about 19 s of wall time, against the 0.5-2 s a stop or a departed caller takes to land
# A departed caller whose leaving is not announced is seen at the end of Fast DDS's 20 s lease
# (twice in full runs): its test's trial lasts about 38 s of wall time.
LEASE_PACE = 0.1


@pytest.fixture
def domain() -> dict[str, str]:
    """An environment with a DDS domain of the test's own, on the loopback only."""
    env = dict(os.environ)
    env["ROS_DOMAIN_ID"] = str(random.randint(1, 100))
    env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    return env


@pytest.fixture
def node(tmp_path: Path, domain: dict[str, str]) -> Iterator[tuple[dict[str, Any], Path]]:
    yield from _node(tmp_path, domain, "scenes/robot.yaml")


@pytest.fixture
def paced_node(tmp_path: Path, domain: dict[str, str]) -> Iterator[tuple[dict[str, Any], Path]]:
    """The node with its simulated trials at PACE times real time: a trial asked to stop, or
    whose caller leaves, is still running when the stop arrives, however busy the machine."""
    yield from _node(tmp_path, domain, "scenes/robot.yaml", pace=PACE)


@pytest.fixture
def lease_paced_node(
    tmp_path: Path, domain: dict[str, str]
) -> Iterator[tuple[dict[str, Any], Path]]:
    """The node paced at LEASE_PACE: a trial outlasts a departed caller's DDS lease."""
    yield from _node(tmp_path, domain, "scenes/robot.yaml", pace=LEASE_PACE)


def _node(
    tmp_path: Path, env: dict[str, str], scene: str, *where: str, pace: float | None = None
) -> Iterator[tuple[dict[str, Any], Path]]:
    """The node on ``scene`` (at ``pace`` times real time, None: as fast as it computes), or
    where ``where`` says (``--config BENCH ...``)."""
    out = tmp_path / "node"
    command = [sys.executable, "-m", "palpate", "ros", *(where or ("--scene", scene)), "--json"]
    if pace is not None:
        command += ["--pace", str(pace)]
    process = subprocess.Popen(
        [*command, "--out", str(out)], env=env, stdout=subprocess.PIPE, text=True
    )
    assert process.stdout is not None
    facts = json.loads(process.stdout.readline())  # printed once the node serves
    try:
        yield facts, out
    finally:
        process.terminate()
        code = process.wait(timeout=WAIT_S)
        process.stdout.close()
        assert code == 0  # SIGTERM: a clean stop


@contextlib.contextmanager
def _trial_under_way(env: dict[str, str]) -> Iterator[subprocess.Popen[str]]:
    """A client that has asked for a trial, once the trial has published 20 joint states."""
    caller = subprocess.Popen(
        [sys.executable, str(CLIENT), "run_trial", "ready@20"],
        env=env,
        stdout=subprocess.PIPE,
        text=True,
    )
    assert caller.stdout is not None
    try:
        assert caller.stdout.readline().strip() == "under way"
        yield caller
    finally:
        if caller.poll() is None:
            caller.kill()
        caller.wait()
        caller.stdout.close()


def client(env: dict[str, str], *calls: str) -> dict[str, Any]:
    done = subprocess.run(
        [sys.executable, str(CLIENT), *calls],
        env=env,
        capture_output=True,
        text=True,
        timeout=WAIT_S,
        check=True,
    )
    return dict(json.loads(done.stdout.splitlines()[-1]))


def test_a_trial_over_ros2_is_the_trial_palpate_sim_runs(
    node: tuple[dict[str, Any], Path], domain: dict[str, str], tmp_path: Path
) -> None:
    seen = client(domain, "run_trial")
    [answer] = seen["answers"]
    assert answer["success"], answer["message"]
    row = json.loads(answer["message"])
    assert json.loads(seen["result"]) == row  # trial/result carries the same row
    expected = simulate_trial(load_scene("scenes/robot.yaml"), 0, log_dir=tmp_path / "cli")
    wanted = json.loads(json.dumps(expected.as_dict()))
    assert {k: v for k, v in row.items() if k != "log"} == {
        k: v for k, v in wanted.items() if k != "log"
    }
    assert Path(row["log"]).is_relative_to(node[1])
    assert read_log(row["log"]).end["state"] == "done"
    # every stream and the latched topics reached a subscriber in another process
    streams = ["measured_js", "measured_cp", "measured_cf", "fbg/strains", "fbg/wavelengths"]
    streams.append("/clock")
    assert all(seen["counts"].get(t, 0) > 20 for t in streams), seen["counts"]
    assert seen["counts"]["/diagnostics"] >= 1
    assert seen["counts"]["trial/result"] == 1
    assert seen["states"][-1] == "done"
    assert "indenting" in seen["states"]
    stamps = seen["stamps"]["measured_js"]
    rate = (len(stamps) - 1) / (stamps[-1] - stamps[0])
    assert rate == pytest.approx(50.0, rel=0.05)  # --rate's default, per second of the clock
    # the tissue pushed back on the tip (-z) by about the beam's buckling load
    assert seen["strongest_push_n"] < -0.1


def test_stop_retracts_the_running_trial(
    paced_node: tuple[dict[str, Any], Path], domain: dict[str, str]
) -> None:
    seen = client(domain, "run_trial", "stop@30")
    trial, stop = seen["answers"]
    assert stop["success"]
    assert "retracts" in stop["message"]
    row = json.loads(trial["message"])
    assert not trial["success"]
    assert row["state"] == "aborted"
    assert row["reason"] == "aborted: stop requested"
    assert seen["states"][-2:] == ["retracting", "aborted"]
    log = read_log(row["log"])
    assert log.end["state"] == "aborted"
    steps = [(r["from"], r["to"]) for r in log.of_kind("transition")]
    assert steps[-1] == ("retracting", "aborted")


def test_a_stop_with_nothing_running_says_so_and_a_named_trial_runs(
    node: tuple[dict[str, Any], Path], domain: dict[str, str]
) -> None:
    seen = client(
        domain, "stop", "trial=S7-bent30-sideways-L42", "run_trial", "trial=nope", "run_trial"
    )
    stop, named, trial, _, unknown = seen["answers"]
    assert not stop["success"]
    assert stop["message"] == "no trial running"
    assert named["success"]
    assert trial["success"]
    assert json.loads(trial["message"])["trial"] == "S7-bent30-sideways-L42"
    assert not unknown["success"]
    assert "no trial 'nope'" in unknown["message"]


def test_a_survey_over_ros2_publishes_its_map(tmp_path: Path, domain: dict[str, str]) -> None:
    for facts, out in _node(tmp_path, domain, "scenes/maps/inclusion.yaml"):
        env = {**domain}
        seen = client(env, "run_trial", "max_probes=4", "run_survey")
        refused, _, survey = seen["answers"]
        assert not refused["success"]
        assert "map scene" in refused["message"]
        assert survey["success"], survey["message"]
        summary = json.loads(survey["message"])
        assert len(summary["probes"]) == seen["counts"]["map/probes"] == 4
        assert seen["counts"]["map/grid"] >= 1
        assert (out / "survey-1" / "probes.jsonl").exists()
        assert facts["node"] == "/palpate/palpate"


def test_the_node_advertises_what_docs_ros2_lists(
    node: tuple[dict[str, Any], Path], domain: dict[str, str]
) -> None:
    facts, _ = node
    topics = {t if t.startswith("/") else f"/palpate/{t}" for t in TOPICS}
    assert set(facts["topics"]) == topics
    assert set(facts["services"]) == {f"/palpate/{s}" for s in SERVICES}
    text = DOCS.read_text(encoding="utf-8")
    for name, (kind, _) in {**TOPICS, **SUBSCRIPTIONS, **SERVICES, **PARAMETERS}.items():
        assert f"| `{name}` | `{kind}` |" in text, name


def test_the_client_docs_ros2_shows_runs_a_trial(
    node: tuple[dict[str, Any], Path], domain: dict[str, str], tmp_path: Path
) -> None:
    blocks = re.findall(r"```python\n(.*?)```", DOCS.read_text(encoding="utf-8"), re.S)
    [shown] = [b for b in blocks if "create_client" in b]
    script = tmp_path / "client_doc.py"
    script.write_text(shown, encoding="utf-8")
    done = subprocess.run(
        [sys.executable, str(script)],
        env=domain,
        capture_output=True,
        text=True,
        timeout=WAIT_S,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.split()[0] == "S7-straight-downward-L42"


def test_sigterm_mid_trial_retracts_and_leaves_a_complete_log(
    tmp_path: Path, domain: dict[str, str]
) -> None:
    out = tmp_path / "node"
    command = [sys.executable, "-m", "palpate", "ros", "--json", "--out", str(out)]
    node = subprocess.Popen(command, env=domain, stdout=subprocess.PIPE, text=True)
    assert node.stdout is not None
    json.loads(node.stdout.readline())
    try:
        with _trial_under_way(domain):
            node.terminate()
            assert node.wait(timeout=WAIT_S) == 0
    finally:
        node.stdout.close()
    [found] = (out / "logs").glob("*.jsonl")
    log = read_log(found)
    assert log.end["state"] == "aborted"
    assert log.end["reason"] == "aborted: stop requested"
    assert read_recording(found.with_suffix(".mcap")).complete


def _moved_and_held(jog: dict[str, Any]) -> None:
    """The jog moved 1 mm on command; silent, it came to a stop and stood still (a robot that
    jogged on and on would never give the client its still second), within the command timeout
    and the two ways' latencies of the jog's 2 mm/s."""
    quiet = jog["quiet"]
    # the largest: a joint state can reach the client after a newer one (once, in a fresh
    # clone's CI, the first one in read 5 ticks short of the 1 mm the client had seen)
    assert max(a for _, a in quiet) >= jog["start"] + 1e-3 - 20e-6
    moved = [t for (_, a), (t, b) in itertools.pairwise(quiet) if a != b]
    stopped = max(moved, default=quiet[0][0])
    held = [a for t, a in quiet if t >= stopped]
    assert quiet[-1][0] - stopped >= STILL_S  # the client waited for it: it stood still
    assert max(held) - min(held) < 5e-6
    # the node holds COMMAND_TIMEOUT_S after the last command it *received*; the client's quiet
    # starts when it has *seen* 1 mm: DDS delivery and the two processes' scheduling add up to
    # some hundreds of ms either way (1.25 s of jogging on was seen once, on a busy machine)
    assert max(held) - quiet[0][1] < 2e-3 * (COMMAND_TIMEOUT_S + 2 * LATENCY_S)


def test_servo_jp_moves_the_robot_and_zero_takes_the_strains_zero_at_rest(
    node: tuple[dict[str, Any], Path], domain: dict[str, str]
) -> None:
    """A lab controller's CRTK joint goals move the robot through the jog's guards; ``zero``
    answers with the zero its session took, then takes a new one where the robot rests."""
    seen = client(domain, "zero", "servo", "zero")
    first, second = seen["answers"]
    assert first["success"], first["message"]
    assert second["success"], second["message"]
    zeros = [json.loads(a["message"]) for a in (first, second)]
    peaks = {len(z["zero_wavelengths_m"]) for z in zeros} | {len(z["noise_m"]) for z in zeros}
    assert len(peaks) == 1 and peaks != {0}  # noqa: PT018  (one peak count, and peaks)
    assert all(1.4e-6 < w < 1.7e-6 for z in zeros for w in z["zero_wavelengths_m"])
    assert zeros[0] != zeros[1]  # a new zero (new frames), not the first one again
    _moved_and_held(seen["jogs"][0])


def test_a_trial_whose_caller_dies_retracts(
    lease_paced_node: tuple[dict[str, Any], Path], domain: dict[str, str]
) -> None:
    """The client that asked for a trial is terminated mid-trial (its rclpy leaves the DDS graph
    on SIGTERM): the node sees the service's last client gone and stops the trial; it retracts
    and ends ``aborted``."""
    with _trial_under_way(domain) as caller:
        caller.terminate()
        caller.wait(timeout=WAIT_S)
    [result] = client(domain, "result")["answers"]
    row = json.loads(result["message"])
    assert row["state"] == "aborted"
    assert row["reason"] == "aborted: stop requested"
    assert read_log(row["log"]).end["state"] == "aborted"


def test_a_gamepad_jogs_the_robot_and_its_silence_holds_it(
    node: tuple[dict[str, Any], Path], domain: dict[str, str]
) -> None:
    seen = client(domain, "joy", "run_trial")
    [jog] = seen["jogs"]
    _moved_and_held(jog)
    [busy] = seen["answers"]  # the jog holds the robot: no trial meanwhile
    assert not busy["success"]
    assert busy["message"] == "busy: teleop runs"


def test_on_the_bench_the_node_runs_the_bench_files_trials_on_its_ports(
    tmp_path: Path, domain: dict[str, str]
) -> None:
    """``palpate ros --config bench.yaml`` on ``palpate emulate``'s ptys (the SDK and pyserial
    path of the hardware, in real time): the zero at rest, the bench file's trial at a stored
    target named in the parameter, which a stop retracts; its log the bench's."""
    emulate = [sys.executable, "-m", "palpate", "emulate", "--scene", "scenes/robot.yaml"]
    emulator = subprocess.Popen(
        [*emulate, "--seconds", str(WAIT_S), "--json"], stdout=subprocess.PIPE, text=True
    )
    assert emulator.stdout is not None
    try:
        ports = json.loads(emulator.stdout.readline())
        where = ("--config", "bench.yaml", "--servo-port", ports["dynamixel"])
        for facts, _ in _node(tmp_path, domain, "", *where, "--board-port", ports["board"]):
            assert "/clock" not in facts["topics"]  # the bench's clock is the wall's
            seen = client(domain, "zero", "trial=example-downward", "run_trial", "stop@30")
    finally:
        emulator.terminate()
        emulator.communicate(timeout=WAIT_S)
    zero, _, trial, stop = seen["answers"]
    assert zero["success"], zero["message"]
    assert len(json.loads(zero["message"])["zero_wavelengths_m"]) >= 1
    assert stop["success"]
    row = json.loads(trial["message"])
    assert row["trial"] == "01-example-downward-S7"  # the first at that stored target
    assert row["state"] == "aborted"
    assert row["reason"] == "aborted: stop requested"
    assert Path(row["log"]).is_relative_to(tmp_path / "node")
    log = read_log(row["log"])
    assert log.header["source"] == "bench"
    assert log.header["ports"]["servos"] == ports["dynamixel"]
    assert log.end["state"] == "aborted"
    assert seen["counts"]["fbg/wavelengths"] > 20
    assert "/clock" not in seen["counts"]
