"""The live view's cost: a trial's CPU with ``--live`` and a Foxglove client subscribed to every
channel, against the same trials without the view.

The client is a separate process (a websocket client on localhost that subscribes to every
advertised channel and counts the frames, as Foxglove would), so this process's CPU is the
trial's and the server's. Trials of the shipped robot scene, serial, in turns (without, with)
``repeats`` times; per trial the CPU of this process (``time.process_time``: the trial and the
SDK's server threads) and of the trial's own thread (``time.thread_time``). The issue's budget:
``--live`` costs at most 10 % of a trial's CPU.
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import time
from collections.abc import Sequence
from typing import Any

from benchmarks.report import BenchContext, BenchSection, Table
from palpate.campaigns.campaign import campaign_trials, warm_up
from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.estimation.beam.section import sensor_section
from palpate.live import HOST, TOPICS, LiveView
from palpate.simulation.trial import run_sim_trial

CLIENT = """
import json, sys
from websockets.sync.client import connect
frames, topics = 0, {}
with connect(sys.argv[1], subprotocols=["foxglove.sdk.v1"]) as ws:
    print("connected", flush=True)
    while True:
        try:
            frame = ws.recv(timeout=30)
        except Exception:
            break
        if isinstance(frame, str):
            op = json.loads(frame)
            if op.get("op") == "advertise":
                subs = [{"id": c["id"], "channelId": c["id"]} for c in op["channels"]]
                ws.send(json.dumps({"op": "subscribe", "subscriptions": subs}))
                if len(subs) >= int(sys.argv[2]):
                    print("subscribed", flush=True)
        else:
            frames += 1
            if frames % 20 == 0:
                print("frames", frames, flush=True)
"""


def run(ctx: BenchContext) -> BenchSection:
    warm_up()
    scene = load(SceneConfig, resolve("scenes/robot.yaml"))
    stack = load_stack(resolve(scene.robot))
    specs = campaign_trials(scene, stack, ctx.seed)[: 3 if ctx.quick else 6]
    rounds = 2 if ctx.quick else 4
    cpu: dict[str, list[tuple[float, float]]] = {"without": [], "live": []}
    with LiveView(0, stack.sensor, sensor_section(stack.sensor)) as view:
        url = f"ws://{HOST}:{view.port}"
        client = subprocess.Popen(
            [sys.executable, "-c", CLIENT, url, str(len(TOPICS))],
            stdout=subprocess.PIPE,
            text=True,
        )
        try:
            _wait_for(client, "subscribed")
            for _ in range(rounds):
                for mode in ("without", "live"):
                    for spec in specs:
                        t, p = time.thread_time(), time.process_time()
                        run_sim_trial(spec, scene, stack, live=view if mode == "live" else None)
                        cpu[mode].append((time.thread_time() - t, time.process_time() - p))
        finally:
            client.terminate()
            rest, _ = client.communicate(timeout=30)
    counts = [int(line.split()[1]) for line in rest.splitlines() if line.startswith("frames")]
    frames = counts[-1] if counts else 0
    table = _table(cpu, len(specs) * rounds, frames)
    return BenchSection(name="live", tables=[table], summary={**_summary(cpu), "frames": frames})


def _wait_for(client: subprocess.Popen[str], word: str) -> None:
    """Until the client prints ``word`` (it has subscribed to every channel)."""
    assert client.stdout is not None
    for line in client.stdout:
        if line.strip() == word:
            return
    raise RuntimeError("the live view's client ended before it subscribed")


def _median(values: list[tuple[float, float]], i: int) -> float:
    return statistics.median(v[i] for v in values)


def _summary(cpu: dict[str, list[tuple[float, float]]]) -> dict[str, Any]:
    return {
        mode: {"thread_s": _median(v, 0), "process_s": _median(v, 1)} for mode, v in cpu.items()
    }


def _table(cpu: dict[str, list[tuple[float, float]]], trials: int, frames: int) -> Table:
    base_t, base_p = _median(cpu["without"], 0), _median(cpu["without"], 1)
    rows: list[Sequence[Any]] = [
        [
            mode,
            _median(v, 0) * 1e3,
            _median(v, 1) * 1e3,
            f"{_median(v, 0) / base_t:.3f}",
            f"{_median(v, 1) / base_p:.3f}",
        ]
        for mode, v in cpu.items()
    ]
    return Table(
        title="The live view's cost: a simulated robot trial's CPU with a client on every channel",
        columns=["view", "trial thread ms", "process ms", "thread x", "process x"],
        rows=rows,
        note=f"median of {trials} trials each (shipped robot scene, serial, in turns); the client "
        f"is another process and received about {frames} frames; budget: x1.10",
    )
