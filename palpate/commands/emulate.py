"""Start the Dynamixel bus and board emulators on pseudo-terminals and print their paths."""

from __future__ import annotations

import argparse
import contextlib
import json
import logging
import threading

from config import load_stack
from palpate.argtypes import positive_float
from sensor.reader import layout_from_config
from sim.board import BoardEmulator, constant_source
from sim.dynamixel.bus import EmulatedBus

log = logging.getLogger(__name__)


def register(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--config", default="robot.yaml", help="robot configuration YAML")
    parser.add_argument(
        "--seconds",
        type=positive_float,
        default=None,
        help="stop after this long (default: until Ctrl-C)",
    )


def run(args: argparse.Namespace) -> int:
    stack = load_stack(args.config)
    wavelengths = [stack.fbg.base_wavelengths_nm[g - 1] * 1e-9 for g in stack.sensor.used_gratings]
    layout = layout_from_config(stack.sensor, stack.board)
    with (
        EmulatedBus.from_config(stack.servos) as bus,
        BoardEmulator(constant_source(wavelengths), layout, rate_hz=stack.board.rate_hz) as board,
    ):
        ports = {"dynamixel": bus.port, "board": board.port}
        if args.json:
            print(json.dumps(ports), flush=True)
        else:
            print(f"dynamixel bus (Protocol 2.0, {stack.servos.baudrate} bps): {bus.port}")
            print(f"acquisition board ({stack.board.rate_hz:g} frames/s): {board.port}", flush=True)
        log.info("Ctrl-C to stop")
        stop = threading.Event()
        with contextlib.suppress(KeyboardInterrupt):
            stop.wait(args.seconds)
    return 0
