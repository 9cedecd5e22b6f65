"""Start the Dynamixel bus and board emulators on pseudo-terminals and print their paths.

Without ``--scene`` the board streams the sensor at rest (nothing to touch). With ``--scene FILE``
the emulated robot has the scene's samples in front of it, at the poses the bench file's trials name
(``--bench``, default the shipped ``bench.yaml``; ``palpate.simulation.twin.stations_for``), with
the scene's fidelity (noise, imperfection, tube compliance): a rehearsal of the bench on its twin.
``palpate trial --config BENCH.yaml --servo-port PTY --board-port PTY`` then runs end to end exactly
as on the hardware (the same ports, SDK, reader, trial core and logs), in real time.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import logging
import threading
from pathlib import Path
from typing import Any

from palpate.argtypes import non_negative_int, positive_float
from palpate.config import load, load_stack, resolve
from palpate.config.bench import load_bench
from palpate.config.scene import SceneConfig
from palpate.sensor.parser import layout_from_config
from palpate.sim.board import BoardEmulator, constant_source
from palpate.sim.dynamixel.bus import EmulatedBus
from palpate.simulation.twin import SimulatedBench, stations_for

log = logging.getLogger(__name__)


def register(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--config",
        default=None,
        help="robot configuration YAML (default: the bench file's with --scene, else robot.yaml)",
    )
    parser.add_argument(
        "--scene", type=Path, help="put this scene's samples in front of the emulated robot"
    )
    parser.add_argument(
        "--bench",
        default="bench.yaml",
        help="with --scene: the bench file whose trials' stored poses place the samples",
    )
    parser.add_argument(
        "--seed", type=non_negative_int, default=0, help="seed of the emulated FBG noise"
    )
    parser.add_argument(
        "--seconds",
        type=positive_float,
        default=None,
        help="stop after this long (default: until Ctrl-C)",
    )


def run(args: argparse.Namespace) -> int:
    if args.scene is not None:
        return _with_scene(args)
    stack = load_stack(args.config or "robot.yaml")
    wavelengths = [stack.fbg.base_wavelengths_nm[g - 1] * 1e-9 for g in stack.sensor.used_gratings]
    layout = layout_from_config(stack.sensor, stack.board)
    ref_nm, tip = stack.fbg.reference_wavelength_nm, stack.sensor.tip_grating
    source = constant_source(
        wavelengths,
        reference=ref_nm * 1e-9 if layout.has_reference and ref_nm is not None else None,
        force=0.0 if layout.has_force else None,
        tip=None if tip is None else tip.base_wavelength,
    )
    with (
        EmulatedBus.from_config(stack.servos) as bus,
        BoardEmulator(source, layout, rate_hz=stack.board.rate_hz) as board,
    ):
        ports = {"dynamixel": bus.port, "board": board.port}
        _announce(ports, stack.servos.baudrate, stack.board.rate_hz, args)
    return 0


def _with_scene(args: argparse.Namespace) -> int:
    scene = load(SceneConfig, resolve(args.scene))
    loaded = load_bench(args.bench)
    stack = loaded.stack if args.config is None else load_stack(args.config)
    stations = stations_for(scene, loaded)
    with SimulatedBench(stack, scene, wire=True, seed=args.seed, stations=stations) as sim:
        ports = {"dynamixel": sim.servo_port, "board": sim.board_port}
        if not args.json:
            for st in stations:
                print(
                    f"sample {st.sample} in front of tube {st.tube} (stations from {loaded.path})"
                )
        _announce(ports, stack.servos.baudrate, stack.board.rate_hz, args)
    return 0


def _announce(
    ports: dict[str, Any], baudrate: int, rate_hz: float, args: argparse.Namespace
) -> None:
    """Print the ports (JSON with ``--json``) and wait for Ctrl-C or ``--seconds``."""
    if args.json:
        print(json.dumps(ports), flush=True)
    else:
        print(f"dynamixel bus (Protocol 2.0, {baudrate} bps): {ports['dynamixel']}")
        print(f"acquisition board ({rate_hz:g} frames/s): {ports['board']}", flush=True)
        if args.scene is not None:
            print(
                f"run: palpate trial --config {args.bench} --servo-port {ports['dynamixel']} "
                f"--board-port {ports['board']}",
                flush=True,
            )
    log.info("Ctrl-C to stop")
    stop = threading.Event()
    with contextlib.suppress(KeyboardInterrupt):
        stop.wait(args.seconds)
