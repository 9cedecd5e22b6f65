"""Jog roll, advance and tube from the keyboard; live pose, strains and flags; store poses.

A robot with an x-y stage under the sample, or a gantry that carries it (``stage:``), has its
stage jogged too (x/X, y/Y).

``palpate teleop`` runs on the simulator by default (both emulators in-process, real time, a
world with a tissue sample of a scene, so strains and contact respond), on the real bench with
``--config config/bench.yaml``, or on any two ports with ``--servo-port`` and ``--board-port``.
The terminal interface is the standard library's curses (no extra dependency; it runs over ssh
and in tmux, which the tests use); the jog logic and limits are ``robot.teleop``, the screen's
text ``palpate.commands.teleop_screen``. Torque is released on quit, on Ctrl-C, on SIGTERM/SIGHUP
and on a crash.
"""

from __future__ import annotations

import argparse
import contextlib
import curses
import json
import math
import os
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from palpate.argtypes import positive_float
from palpate.commands.teleop_screen import draw, key_name, render, screen_width
from palpate.config import CONFIG_DIR, load, load_stack, resolve
from palpate.config.bench import load_bench
from palpate.config.loader import InputError
from palpate.config.scene import CampaignConfig, SceneConfig
from palpate.config.schema import StackConfig
from palpate.config.targets import save_target
from palpate.estimation.beam.stage import Stage
from palpate.lab.hardware import Hardware, open_hardware, run_on_hardware
from palpate.lab.jog import jog_session, jog_tick
from palpate.live import LiveView, Publisher, add_live_argument, live_view
from palpate.robot.indentation import State
from palpate.robot.rig import ServoFbgRig
from palpate.robot.teleop import Teleop
from palpate.robot.teleop.stagejog import StageJog
from palpate.robot.xystage import StageController
from palpate.sensor.clock import Clock, SystemClock
from palpate.simulation.twin import SimulatedBench

DRAW_PERIOD_S = 0.05


def register(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--config", help="a bench file: real ports, robot, limits, targets")
    parser.add_argument("--servo-port", help="Dynamixel bus port (with --board-port)")
    parser.add_argument("--board-port", help="acquisition board port (with --servo-port)")
    parser.add_argument("--robot", default="robot.yaml", help="robot file with explicit ports")
    parser.add_argument(
        "--scene", default="scenes/robot.yaml", help="simulator: the scene whose tissue is used"
    )
    parser.add_argument("--sample", help="simulator: the scene's sample (default: the first)")
    parser.add_argument("--tube", help="the tube mounted at start (default: the first)")
    parser.add_argument(
        "--targets", type=Path, help="where s saves poses (default: the bench file's targets)"
    )
    parser.add_argument(
        "--rate", type=positive_float, default=100.0, help="control ticks per second"
    )
    add_live_argument(parser, "the jog")


@dataclass
class Session:
    """What the terminal loop drives; built by :func:`run`."""

    model: Teleop
    rig: ServoFbgRig
    clock: Clock
    tick: float
    targets: Path
    title: str
    sim: SimulatedBench | None = None
    saved: list[str] = field(default_factory=list)
    live: LiveView | None = None  # --live: the jog's ticks to Foxglove (palpate.live)
    feed: Publisher | None = None  # the live view's publisher for the current tube
    stage: StageController | None = None  # the x-y stage, when the robot has one
    stage_jog: StageJog | None = None

    def follow_tube(self) -> None:
        """A publisher for the model's current tube (after a swap)."""
        if self.live is not None:
            self.feed = self.live.trial(Stage.on(self.model.tube, 0.0))


@dataclass
class _Where:
    """What teleop drives: the robot's configuration, the ports and how the title names them."""

    stack: StackConfig
    campaign: CampaignConfig
    targets: Path
    mode: str
    ports: dict[str, Any] = field(default_factory=dict)
    sim: SimulatedBench | None = None


def run(args: argparse.Namespace) -> int:
    if not (sys.stdin.isatty() and sys.stdout.isatty()):
        raise InputError("palpate teleop needs a terminal (stdin and stdout)")
    if not 1.0 <= args.rate <= 1000.0:
        raise InputError(f"--rate: {args.rate} outside 1..1000 ticks per second")
    if (args.servo_port is None) != (args.board_port is None):
        raise InputError("--servo-port and --board-port go together")
    where = _where(args)
    if args.targets is not None:
        where.targets = args.targets
    _check_tube(where.stack, args.tube)
    summary: dict[str, Any] = {}
    code = run_on_hardware("teleop", lambda: _body(where, args, summary), stopped_exit=0)
    if code or not summary:
        return code
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        for name in summary["saved"]:
            print(f"saved target {name!r} in {summary['targets']}")
        print(f"final state {summary['state']}; torque off")
    return 0


def _where(args: argparse.Namespace) -> _Where:
    """The bench file's robot and ports, the given ports, or the simulator (the default)."""
    if args.config is not None:
        loaded = load_bench(args.config)
        ports = {
            "servo_key": f"servos.port in {loaded.path}",
            "board_key": f"board.port in {loaded.path}",
        }
        b = loaded.bench
        where = _Where(loaded.stack, b.campaign, loaded.targets_path, f"bench {loaded.path}", ports)
    elif args.servo_port is not None:
        ports = {"servo_key": "--servo-port", "board_key": "--board-port"}
        mode = f"ports {args.servo_port} {args.board_port}"
        targets = CONFIG_DIR / "targets.yaml"
        where = _Where(load_stack(args.robot), CampaignConfig(), targets, mode, ports)
    else:
        return _simulator(args)
    where.ports.update(servo_port=args.servo_port, board_port=args.board_port)
    return where


def _simulator(args: argparse.Namespace) -> _Where:
    scene = load(SceneConfig, resolve(args.scene))
    stack = load_stack(resolve(scene.robot))
    _check_tube(stack, args.tube)
    sim = SimulatedBench(stack, scene, sample=args.sample, tube=args.tube, wire=False)
    s = sim.sample
    mode = f"simulator: sample {s.name} ({s.modulus_kpa:g} kPa), scene {scene.name}"
    ports = {"servo_port": sim.servo_port, "board_port": sim.board_port}
    return _Where(stack, scene.campaign, CONFIG_DIR / "targets.yaml", mode, ports, sim)


def _body(where: _Where, args: argparse.Namespace, summary: dict[str, Any]) -> int:
    """Open the robot, zero the sensor, run the terminal loop; torque off on the way out."""
    with contextlib.ExitStack() as stack_:
        if where.sim is not None:
            stack_.enter_context(where.sim)
        hw = stack_.enter_context(open_hardware(where.stack, clock=SystemClock(), **where.ports))
        session = _session(where.stack, where.campaign, hw, args, where.targets)
        if hw.stage is not None and where.stack.stage is not None:
            session.stage = hw.stage
            session.stage_jog = StageJog(where.stack.stage, hw.stage.position)
        session.title = f"palpate teleop ({where.mode})"
        session.sim = where.sim
        session.live = stack_.enter_context(live_view(args.live, where.stack))
        session.follow_tube()
        try:
            os.environ.setdefault("ESCDELAY", "25")  # a lone Esc cancels at once
            summary.update(curses.wrapper(_loop, session))
        finally:
            session.rig.release()
    return 0


def _check_tube(stack: StackConfig, name: str | None) -> None:
    if name is not None and name not in [t.name for t in stack.tubes]:
        raise InputError(f"--tube: no tube {name!r}; known: {[t.name for t in stack.tubes]}")


def _session(
    stack: StackConfig,
    campaign: CampaignConfig,
    hw: Hardware,
    args: argparse.Namespace,
    targets: Path,
) -> Session:
    tick = 1.0 / args.rate
    model, rig = jog_session(stack, campaign, hw, tick, args.tube)
    return Session(model, rig, hw.clock, tick, targets, "palpate teleop")


def _loop(stdscr: Any, s: Session) -> dict[str, Any]:
    with contextlib.suppress(curses.error):
        curses.curs_set(0)
    stdscr.nodelay(True)
    stdscr.keypad(True)
    model, rig, clock = s.model, s.rig, s.clock
    recovered = False
    next_draw = next_tick = clock.now()
    while True:
        while (code := stdscr.getch()) != -1:
            name = key_name(code)
            if name is not None and _stage_key(s, name):
                continue
            effect = model.press(name) if name is not None else None
            if effect is None:
                continue
            if effect.kind == "quit":
                return _summary(s)
            if effect.kind == "save":
                _save(s, effect.value)
            elif effect.kind == "recover":
                recovered = False
                if not rig.recover():
                    model.fail("could not clear the servo fault: power-cycle the servos")
            elif effect.kind == "tube":
                s.follow_tube()
                if s.sim is not None:  # the operator swapped the tube
                    s.sim.tube = s.sim.stack.tube(effect.value)
        obs, recovered = jog_tick(model, rig, clock, recovered)
        if s.stage is not None and s.stage_jog is not None:
            if model.state is not State.IDLE and model.state is not State.POSITIONING:
                s.stage_jog.goal = s.stage.position  # a stop or a fault: the stage holds too
            s.stage.follow(s.stage_jog.goal)
        if s.feed is not None:
            s.feed(obs, model.state)
        now = clock.now()
        if now >= next_draw:
            draw(stdscr, render(model.view(), screen_width(stdscr), s.title, _stage_view(s)))
            next_draw = now + DRAW_PERIOD_S
        # fell behind (a slow draw)? then do not try to catch up in a burst
        next_tick = max(next_tick + s.tick, now)
        clock.sleep(next_tick - now)


def _stage_key(s: Session, name: str) -> bool:
    """A stage jog key (not while a name is typed): the stage's goal moves if the tip is free
    (no contact, the jog model idle); True when the key was the stage's."""
    model, jog = s.model, s.stage_jog
    if jog is None or model.prompt is not None:
        return False
    obs = model.obs
    free = obs is not None and not obs.contact and model.state is State.IDLE
    if not jog.press(name, step=model.step_size[0], free=free):
        return False
    model.message = jog.message
    return True


def _stage_view(s: Session) -> tuple[tuple[float, float], tuple[float, float]] | None:
    """The stage's measured position and its jog goal (m), for the screen."""
    if s.stage is None or s.stage_jog is None:
        return None
    return s.stage.read(), s.stage_jog.goal


def _save(s: Session, name: str) -> None:
    try:
        save_target(s.targets, s.model.target(name, note="saved by palpate teleop"))
    except (OSError, ValueError) as exc:
        s.model.message = f"not saved: {exc}"
        return
    s.saved.append(name)
    s.model.message = f"saved pose {name!r} in {s.targets}"


def _summary(s: Session) -> dict[str, Any]:
    obs = s.model.obs
    return {
        "state": s.model.state.value,
        "tube": s.model.tube.name,
        "roll_deg": None if obs is None else math.degrees(obs.roll),
        "translation_mm": None if obs is None else obs.advance * 1e3,
        "saved": s.saved,
        "targets": str(s.targets),
    }
