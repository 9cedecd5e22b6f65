"""One simulated trial, wired exactly like the bench: emulators in, control stack on top.

The world (``sim.world``, built by :mod:`palpate.simulation.world`) feeds the servo emulator and the
board emulator on one virtual clock; the control stack drives the servos through dynamixel-sdk
and reads FBG frames through the frame reader, and the trial core (:mod:`robot.trial`, the same
as on the bench) plans, runs, estimates and records the trial. ``transport="wire"`` puts both
emulators on pseudo-terminals (dynamixel-sdk's packets, pyserial's bytes). ``"fast"`` keeps the
same driver, drive, rig, reader and trial loop and skips the bytes no one looks at: the driver's
SDK calls go to the emulated servos' control tables (``sim.dynamixel.direct``). With a fault hook
(``palpate sim --faults``), whose faults act on bytes, ``"fast"`` keeps the SDK and the parsers
and only replaces the ptys by in-process transports (``sim.inprocess``).
"""

from __future__ import annotations

import contextlib
import dataclasses
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, Literal, Protocol

from palpate.config.sample import AssumedConfig
from palpate.config.scene import CampaignConfig, FidelityConfig, SceneConfig
from palpate.config.schema import ServoBusConfig, StackConfig
from palpate.estimation.beam.stage import Stage
from palpate.live import View
from palpate.robot.drive import DriveController
from palpate.robot.dynamixel.driver import DynamixelBus
from palpate.robot.indentation import Observation, Prober, State, TrialPlan
from palpate.robot.records.log import TrialLogWriter
from palpate.robot.rig import RigSettings, ServoFbgRig
from palpate.robot.trial.record import header_common
from palpate.robot.trial.session import TrialSetup, run_session_trial
from palpate.robot.trial.setup import (
    prober_for,
    rig_settings,
    sensor_section,
    trial_plan,
)
from palpate.sensor.parser import layout_from_config
from palpate.sensor.reader import FrameReader
from palpate.sim.board import BoardEmulator, BoardFaults
from palpate.sim.clock import VirtualClock
from palpate.sim.dynamixel.bus import EmulatedBus
from palpate.sim.dynamixel.direct import direct_transport
from palpate.sim.dynamixel.timing import BusTiming
from palpate.sim.inprocess import FramePipe, InProcessPort, MemorySerial
from palpate.sim.world import World
from palpate.simulation.result import (
    TrialOutcome,
    estimate_sim_trial,
    estimator_inputs,
    outcome_of,
    trial_stage,
)
from palpate.simulation.world import (
    ServoJoints,
    TrialGeometry,
    TrialSpec,
    tissue_model,
    trial_geometry,
    trial_sample,
    trial_stack,
    trial_world,
)

# The simulated trial's public names; the spec, the geometry and the tissue are simworld's.
__all__ = [
    "EmulatorHook",
    "Transport",
    "TrialOutcome",
    "TrialSpec",
    "run_sim_trial",
    "tissue_model",
    "trial_geometry",
]

Transport = Literal["fast", "wire"]


class EmulatorHook(Protocol):
    """Fault injection and ground-truth checks around one trial's emulators
    (``palpate.faults.FaultInjector``); the control stack never sees it."""

    @property
    def board_faults(self) -> BoardFaults | None: ...

    def make_bus(self, cfg: ServoBusConfig, clock: VirtualClock) -> EmulatedBus: ...

    def attach(
        self, clock: VirtualClock, bus: EmulatedBus, board: BoardEmulator, world: World
    ) -> None:
        """Called once the emulators exist, before the control stack connects."""
        ...

    def log_opened(self, log: TrialLogWriter) -> None: ...

    def detach(self) -> None:
        """Called after the control stack has closed its ports, before the emulators stop."""
        ...


@contextlib.contextmanager
def _emulators(
    transport: Transport,
    stack: StackConfig,
    clock: VirtualClock,
    world: World,
    hook: EmulatorHook | None = None,
    timing: BusTiming | None = None,
) -> Iterator[tuple[EmulatedBus, BoardEmulator, Any, Any, Any]]:
    """The emulators of one trial and the control stack's ends of them: (bus, board, servo
    port, packet handler or None for the SDK's, board port)."""
    if hook is None:
        bus = EmulatedBus.from_config(stack.servos, clock=clock)
    else:
        bus = hook.make_bus(stack.servos, clock)
    bus.timing = timing
    faults = None if hook is None else hook.board_faults
    layout = layout_from_config(stack.sensor, stack.board)
    rate = stack.board.rate_hz
    handler: Any = None
    if transport == "wire":
        board = BoardEmulator(world.sample, layout, rate_hz=rate, clock=clock, faults=faults)
        port = bus.open()
        servo_port: Any = port
        board_port: Any = board.port
    elif hook is None:  # nothing needs the bytes: registers and frames in memory
        frames = FramePipe()
        board = BoardEmulator(world.sample, layout, rate_hz=rate, clock=clock, frame_sink=frames)
        board_port = frames
        servo_port, handler = direct_transport(bus)
    else:  # the faults act on bytes: SDK packets and encoded frames, in memory
        pipe = MemorySerial()
        board = BoardEmulator(
            world.sample, layout, rate_hz=rate, clock=clock, sink=pipe, faults=faults
        )
        board_port = pipe
        servo_port = InProcessPort(bus)
        # in-process a reply is there at once or never: with injected packet loss, do not
        # spin 20 ms of wall time per lost reply (simulated time is not affected)
        servo_port.reply_timeout_ms = 1.0
    if hook is not None:
        hook.attach(clock, bus, board, world)
    try:
        yield bus, board, servo_port, handler, board_port
    finally:
        if hook is not None:
            hook.detach()
        board.stop()
        bus.close()  # no-op on the fast path (no pty)


def trial_campaign(spec: TrialSpec, scene: SceneConfig) -> CampaignConfig:
    """The scene's campaign at the trial's own indentation speed, when it has one."""
    if spec.indent_speed is None:
        return scene.campaign
    return dataclasses.replace(scene.campaign, indent_speed_mm_per_s=spec.indent_speed * 1e3)


def run_sim_trial(
    spec: TrialSpec,
    scene: SceneConfig,
    stack: StackConfig,
    *,
    transport: Transport = "fast",
    log_dir: Path | None = None,
    keep_series: bool = False,
    hook: EmulatorHook | None = None,
    live: View | None = None,
    stop: Callable[[], bool] | None = None,
) -> TrialOutcome:
    """One simulated trial, estimated; ``live``: its view, ``stop``: asked each tick (run_trial)."""
    c = trial_campaign(spec, scene)
    geo = trial_geometry(stack, spec, trial_sample(scene, spec))
    retract = geo.contact_translation - c.standoff - 1e-3
    stack = trial_stack(scene, stack, geo, retract)
    plan = trial_plan(c, stack, roll=geo.plan_roll, contact=geo.contact_translation, home=retract)
    clock = VirtualClock()
    servos = ServoJoints(stack)
    world = trial_world(spec, scene, stack, geo, servos)
    series: dict[str, list[float]] = {}
    stage = trial_stage(spec, stack, geo)
    on_tick = _on_tick(world, series if keep_series else None, live, stage)
    timing = bus_timing(scene.fidelity, stack.servos)
    with _emulators(transport, stack, clock, world, hook, timing) as emulators:
        bus, board, servo_port, handler, board_port = emulators
        servos.bus = bus
        driver = DynamixelBus.from_config(
            _reply_timeout(stack, transport, hook), port=servo_port, packet_handler=handler
        )
        reader = FrameReader.from_config(board_port, stack.sensor, stack.board, clock=clock)
        settings = _rig_settings(
            spec, scene, stack, fast_faults=hook is not None and transport == "fast"
        )
        # the rig waits each tick for exactly what the board has sent, never for a frame not sent
        settings = dataclasses.replace(settings, sent_bytes=lambda: board.stats.bytes_sent)
        with DriveController(driver, stack.drive) as drive, reader:
            board.start()
            rig = ServoFbgRig.for_stack(drive, reader, stack, clock, settings)
            setup = TrialSetup(
                plan,
                c,
                stack,
                estimate=lambda result: estimate_sim_trial(result, spec, scene, stack, geo),
                log_path=None if log_dir is None else log_dir / f"{spec.trial_id}.jsonl",
                header=_header(spec, scene, stack, plan, geo),
                mcap=scene.mcap,
                prober=_prober(spec, scene, stack, stage),
                on_tick=on_tick,
                on_log=None if hook is None else hook.log_opened,
                # the world's truth the controller never sees, for the report (and --resume)
                before_estimate=lambda _: [_world_record(world)],
                stop=stop,
            )
            done = run_session_trial(rig, clock, setup)
    outcome = outcome_of(spec, geo, done.result, done.estimate, done.log_path, series)
    outcome.true_misalignment = _truth(world)
    outcome.true_motion = _moved(world)
    return outcome


def _world_record(world: World) -> dict[str, object]:
    """The log's ``world`` record: the truth the controller never sees."""
    return {"kind": "world", "true_misalignment": _truth(world), "true_motion": _moved(world)}


def _moved(world: World) -> float | None:
    """How far the surface moved while the tip touched it (m; the range of its breathing
    displacement), None for a world that does not breathe or a trial without contact."""
    if world.breath is None or world.moved is None:
        return None
    return world.moved[1] - world.moved[0]


def _truth(world: World) -> float | None:
    """The misalignment the world's indentation had (rad), None before any."""
    indentation = world.indentation
    return None if indentation is None else indentation.misalignment


def bus_timing(fidelity: FidelityConfig, servos: ServoBusConfig) -> BusTiming | None:
    """The servo bus's timing model for a scene's fidelity (None: ideal, replies at once)."""
    if fidelity.bus_timing == "ideal":
        return None
    baud = fidelity.bus_baudrate if fidelity.bus_baudrate is not None else servos.baudrate
    return BusTiming(baudrate=baud, latency_timer_s=fidelity.latency_timer)


SIM_REPLY_TIMEOUT_MS = 2000.0


def _reply_timeout(
    stack: StackConfig, transport: Transport, hook: EmulatorHook | None
) -> ServoBusConfig:
    """The servo bus as the driver sees it: over ptys the emulator answers from a thread that a
    busy machine may not run for a while, so a reply may be late but is never lost, and a
    generous timeout keeps the trial independent of the machine's load. With fault injection
    (replies really lost) the configured timeout stands."""
    servos = stack.servos
    if transport == "wire" and hook is None:
        servos = dataclasses.replace(
            servos, timeout_ms=max(servos.timeout_ms, SIM_REPLY_TIMEOUT_MS)
        )
    return servos


def _rig_settings(
    spec: TrialSpec, scene: SceneConfig, stack: StackConfig, *, fast_faults: bool
) -> RigSettings:
    settings = rig_settings(
        scene.campaign,
        stack,
        1.0 / scene.control_rate_hz,
        sync_to_clock=True,
        exposed_length=spec.exposed_length,
    )
    if fast_faults:
        # in-process frames arrive during the clock advance or never: with injected board
        # faults, do not wait 0.2 s of wall time for each lost frame
        settings = dataclasses.replace(settings, frame_wait_s=0.0)
    return settings


def _on_tick(
    world: World,
    series: dict[str, list[float]] | None,
    live: View | None,
    stage: Stage,
) -> Callable[[Observation, State], None] | None:
    """The trial's ``on_tick``: the series recorder (with ``series``), the live view's feed."""
    recorder = None if series is None else _series_recorder(world, series)
    feed = None if live is None else live.trial(stage)
    return _ticks(recorder, feed)


def _ticks(
    *hooks: Callable[[Observation, State], None] | None,
) -> Callable[[Observation, State], None] | None:
    """One ``on_tick`` calling each given hook in turn (None without any)."""
    given = [h for h in hooks if h is not None]
    if not given:
        return None
    if len(given) == 1:
        return given[0]

    def on_tick(obs: Observation, state: State) -> None:
        for hook in given:
            hook(obs, state)

    return on_tick


def _series_recorder(
    world: World, series: dict[str, list[float]]
) -> Callable[[Observation, State], None]:
    """An ``on_tick`` that fills ``series``: stage advance, the world's true load, strains."""
    series.update(advance=[], force=[], s1=[], s2=[], s3=[])

    def on_tick(obs: Observation, state: State) -> None:
        st = world.last
        series["advance"].append(obs.advance)
        series["force"].append(st.P if st else 0.0)
        for k, s in zip(("s1", "s2", "s3"), obs.strains, strict=False):
            series[k].append(s)

    return on_tick


def _header(
    spec: TrialSpec,
    scene: SceneConfig,
    stack: StackConfig,
    plan: TrialPlan,
    geo: TrialGeometry,
) -> dict[str, Any]:
    tube = trial_stage(spec, stack, geo).tube
    inputs = estimator_inputs(spec, scene, stack, geo)
    return {
        "trial": spec.trial_id,
        "source": "simulation",
        "spec": spec.record(),
        "scene": scene.name,
        **header_common(plan, sensor_section(stack), stack.sensor, tube, inputs.poisson, inputs),
    }


def _prober(
    spec: TrialSpec, scene: SceneConfig, stack: StackConfig, stage: Stage
) -> Callable[[TrialPlan], Prober] | None:
    """A robot trial's probing step, told the convex surface's radius the operator believes
    for its sample (its ``assumed:``, else its own); None on the bench or without probing."""
    if stage.tube is None:
        return None
    sample = trial_sample(scene, spec)
    radius = (sample.assumed or AssumedConfig()).surface_radius(sample.curvature_radius)
    return prober_for(trial_campaign(spec, scene), stack, stage.tube, radius)
