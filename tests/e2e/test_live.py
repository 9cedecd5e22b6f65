"""The live view (``palpate.live``): a websocket client on localhost receives every advertised
channel during a simulated trial; the server listens on loopback only and is gone when the view
closes; a bad ``--live`` port exits 2 naming the option."""

from __future__ import annotations

import contextlib
import dataclasses
import json
import socket
import threading
import time
from pathlib import Path

import pytest
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

from palpate.cli import main
from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.estimation.beam.section import sensor_section
from palpate.live import HOST, TOPICS, LiveView
from palpate.simulation.trial import TrialSpec, run_sim_trial

STACK = load_stack()
ROBOT = load(SceneConfig, resolve("scenes/robot.yaml"))
BOUND = 120.0  # s: generous bounds on waiting, never a measured time
SUBPROTOCOL = "foxglove.sdk.v1"


class Client:
    """Subscribes to every channel the server advertises; records the topics it gets data on."""

    def __init__(self, port: int, wanted: frozenset[str] = frozenset(TOPICS)) -> None:
        self.port = port
        self.wanted = wanted
        self.advertised: set[str] = set()
        self.received: set[str] = set()
        self.subscribed = threading.Event()
        self.complete = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        with (
            contextlib.suppress(ConnectionClosed),
            connect(f"ws://{HOST}:{self.port}", subprotocols=[SUBPROTOCOL]) as ws,
        ):
            channels: dict[str, int] = {}  # topic -> its newest channel id
            topics: dict[int, str] = {}  # subscription id -> topic
            deadline = time.monotonic() + BOUND
            retry = time.monotonic() + 1.0

            def subscribe(topic: str) -> None:
                sid = len(topics) + 1  # a fresh subscription id each request
                topics[sid] = topic
                sub = [{"id": sid, "channelId": channels[topic]}]
                ws.send(json.dumps({"op": "subscribe", "subscriptions": sub}))

            while not self.complete.is_set() and time.monotonic() < deadline:
                if time.monotonic() > retry:
                    # a subscription the server refused ("unknown channel": a request that
                    # raced the channel's registration, or a trial's channel already gone)
                    # is asked again, once a second, while its topic has not been heard
                    for topic in (self.wanted & channels.keys()) - self.received:
                        subscribe(topic)
                    retry = time.monotonic() + 1.0
                try:
                    frame = ws.recv(timeout=1.0)
                except TimeoutError:
                    continue
                if isinstance(frame, str):
                    op = json.loads(frame)
                    if op.get("op") == "advertise":
                        new = {c["topic"]: c["id"] for c in op["channels"]}
                        channels.update(new)
                        self.advertised.update(new)
                        # one request a channel: a refused one must not take the others with it
                        for topic in new:
                            subscribe(topic)
                        if self.wanted <= self.advertised:
                            self.subscribed.set()
                    continue
                if frame[0] == 1:  # message data: opcode, subscription id (u32 LE), time, payload
                    self.received.add(topics[int.from_bytes(frame[1:5], "little")])
                    if self.wanted <= self.received:
                        self.complete.set()


def test_a_client_on_localhost_gets_every_channel_during_a_trial(tmp_path: Path) -> None:
    with LiveView(0, STACK.sensor, sensor_section(STACK.sensor)) as view:
        client = Client(view.port)
        assert client.subscribed.wait(BOUND), client.advertised
        spec = TrialSpec("S8-bent30-down", "robot", "S8", 314.53e3, 0.45, STACK.tube("bent30"),
                         "downward", 0.0, 42e-3, 1)  # fmt: skip
        out = run_sim_trial(spec, ROBOT, STACK, log_dir=tmp_path, live=view)
        assert out.state in ("done", "unreachable"), out.reason
        # the trial publishes 25 times a second of wall time at most; let it go on publishing
        # (rerun trials) until the client has seen every channel, within the bound
        for seed in range(2, 12):
            if client.complete.wait(0.0):
                break
            again = dataclasses.replace(spec, trial_id=f"again{seed}", seed=seed)
            run_sim_trial(again, ROBOT, STACK, live=view)
        assert client.complete.wait(BOUND), (client.advertised, client.received)
        assert set(TOPICS) <= client.received
        port = view.port
        others = _non_loopback_address()
        if others is not None:  # the server is bound to loopback only
            with pytest.raises(ConnectionRefusedError):
                socket.create_connection((others, port), timeout=5).close()
    assert _refused_within(HOST, port, BOUND)  # closed with the view (its listener stops a moment
    # after stop() returns: waited for, within the bound)


@pytest.mark.slow
def test_a_map_survey_shows_its_map_live() -> None:
    """``palpate map --live``: the map and the probes reach a client as point clouds."""
    from palpate.campaigns.survey import publish_map, run_survey

    scene = load(SceneConfig, resolve("scenes/maps/inclusion.yaml"))
    wanted = frozenset({"/map/grid", "/map/probes"})
    with LiveView(0, STACK.sensor, sensor_section(STACK.sensor)) as view:
        client = Client(view.port, wanted)
        result = run_survey(scene, STACK, strategy="raster", max_probes=4, live=view)
        assert result.summary is not None
        # the channels open with their first frame and a client busy beside the simulator may
        # miss a frame: the last map is published again until the client has seen both
        for _ in range(400):
            if client.complete.wait(0.05):
                break
            publish_map(view, result.probes, result.patch, None, result.length_scale_max)
        assert client.complete.wait(BOUND), (client.advertised, client.received)
    assert wanted <= client.received


def _refused_within(host: str, port: int, bound: float) -> bool:
    """Whether connections to ``host:port`` are refused before ``bound`` seconds pass."""
    deadline = time.monotonic() + bound
    while time.monotonic() < deadline:
        try:
            socket.create_connection((host, port), timeout=5).close()
        except ConnectionRefusedError:
            return True
        except ConnectionResetError:
            pass  # the listener closed with this connection in its backlog: closing, poll on
        threading.Event().wait(0.05)  # the condition is polled, not a timed expectation
    return False


def _non_loopback_address() -> str | None:
    try:
        address = socket.gethostbyname(socket.gethostname())
    except OSError:
        return None
    return None if address.startswith("127.") else address


@pytest.mark.parametrize("value", ["70000", "-1", "web"])
def test_a_bad_live_port_exits_2_naming_the_option(
    value: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["sim", "--campaign", "bench", "--live", value]) == 2
    assert "--live" in capsys.readouterr().err


@pytest.mark.parametrize("tube", ["straight", "bent30", "bent50"])
def test_the_drawn_tube_ends_at_the_kinematics_tip(tube: str) -> None:
    import numpy as np

    from palpate.live import _beam_points, _tube
    from palpate.robot.kinematics import forward

    config = STACK.tube(tube)
    points, tip, rotation = _tube(config, 0.7, 0.05)
    np.testing.assert_allclose(tip, forward(config, 0.7, 0.05).tube_tip, atol=1e-12)
    pose = forward(config, 0.7, 0.05)
    assert np.all(np.isfinite(points))
    np.testing.assert_allclose(points[-1], pose.tube_tip, atol=1e-12)
    np.testing.assert_allclose(rotation, pose.rotation, atol=1e-12)
    straight = _beam_points(0.042, 0.0)  # below buckling: the sensor straight along x
    assert straight[-1][0] == pytest.approx(0.042)
    bent = _beam_points(0.042, 0.042 * 0.02)  # e/L = 0.02: the elastica, its pin on the axis
    assert bent[-1][0] == pytest.approx(0.042 * 0.98, rel=1e-6)
    assert max(abs(p[2]) for p in bent) > 1e-3
