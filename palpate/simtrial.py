"""One simulated trial, wired exactly like the bench: emulators in, control stack on top.

The world (``sim.world``, built by :mod:`palpate.simworld`) feeds the servo emulator and the
board emulator on one virtual clock; the control stack drives the servos through dynamixel-sdk
and reads FBG frames through the frame reader, and the trial core (:mod:`robot.trial`, the same
as on the bench) plans, runs, estimates and records the trial. ``transport="wire"`` puts both
emulators on pseudo-terminals; ``"fast"`` keeps the same SDK, driver, reader and parser and only
replaces the ptys by in-process transports (``sim.inprocess``).
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, Protocol

from config.scene import SceneConfig
from config.schema import ServoBusConfig, StackConfig
from estimation.jointfit import JointFit
from estimation.stiffness import StiffnessEstimate
from palpate.simworld import (
    ServoJoints,
    TrialGeometry,
    TrialSpec,
    tissue_model,
    trial_geometry,
    trial_sample,
    trial_stack,
    trial_world,
)
from robot.drive import DriveController
from robot.dynamixel.driver import DynamixelBus
from robot.indentation import Observation, State, TrialMarks, TrialPlan
from robot.rig import RigSettings, ServoFbgRig
from robot.trial.estimate import EstimatorInputs, TrialEstimate, estimate_trial
from robot.trial.log import TrialLogWriter
from robot.trial.record import end_record, estimate_record, header_common
from robot.trial.run import TrialResult, run_trial
from robot.trial.setup import detector_for, guards_for, rig_settings, sensor_section, trial_plan
from sensor.reader import FrameReader, layout_from_config
from sensor.strain import StrainChain
from sim.board import BoardEmulator, BoardFaults
from sim.clock import VirtualClock
from sim.dynamixel.bus import EmulatedBus
from sim.inprocess import InProcessPort, MemorySerial
from sim.world import World
from wire.dynamixel import TICKS_PER_REV

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


@dataclass
class TrialOutcome:
    spec: TrialSpec
    state: str
    reason: str
    estimate: StiffnessEstimate | None
    exposed_length_at_buckling: float | None
    ik_residual: float
    ticks: int
    sim_time: float
    log_path: str | None
    series: dict[str, list[float]] = field(default_factory=dict)
    marks: TrialMarks | None = None  # encoder at contact and at buckling, strains at buckling
    joint: JointFit | None = None  # the contact-point-free estimate (robot.trial.estimate)
    joint_seconds: float | None = None  # wall time of the joint fit (for reports, not tests)

    def modulus(self, method: str = "joint") -> float | None:
        """E (Pa) by ``"joint"`` (the whole-record fit) or ``"paper"`` (Eqs. 13-14)."""
        if method == "joint":
            return None if self.joint is None else self.joint.modulus
        if method == "paper":
            return None if self.estimate is None else self.estimate.modulus
        raise ValueError(f"method must be 'joint' or 'paper', got {method!r}")

    def as_dict(self) -> dict[str, Any]:
        est = self.estimate
        jf = self.joint

        def kpa(v: float | None) -> float | None:
            return None if v is None else v / 1e3

        return {
            "trial": self.spec.trial_id,
            "sample": self.spec.sample,
            "tube": self.spec.tube,
            "orientation": self.spec.orientation,
            "exposed_length_mm": self.spec.exposed_length * 1e3,
            "actual_kpa": self.spec.modulus / 1e3,
            "estimated_kpa": None if est is None or est.modulus is None else est.modulus / 1e3,
            "delta_mm": None if est is None else est.delta * 1e3,
            "force_n": None if est is None else est.force,
            "joint_kpa": kpa(None if jf is None else jf.modulus),
            "joint_ci_kpa": None if jf is None else [kpa(jf.ci_low), kpa(jf.ci_high)],
            "joint_contact_mm": None if jf is None or jf.contact is None else jf.contact * 1e3,
            "joint_message": "no loading record" if jf is None else jf.message,
            "warnings": [] if jf is None else list(jf.warnings),
            "state": self.state,
            "reason": self.reason,
            "ik_residual_deg": math.degrees(self.ik_residual),
            "sim_time_s": self.sim_time,
            "log": self.log_path,
        }


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
) -> Iterator[tuple[EmulatedBus, BoardEmulator, Any, Any]]:
    if hook is None:
        bus = EmulatedBus.from_config(stack.servos, clock=clock)
    else:
        bus = hook.make_bus(stack.servos, clock)
    faults = None if hook is None else hook.board_faults
    layout = layout_from_config(stack.sensor, stack.board)
    rate = stack.board.rate_hz
    if transport == "wire":
        board = BoardEmulator(world.sample, layout, rate_hz=rate, clock=clock, faults=faults)
        port = bus.open()
        servo_port: Any = port
        board_port: Any = board.port
    else:
        pipe = MemorySerial()
        board = BoardEmulator(
            world.sample, layout, rate_hz=rate, clock=clock, sink=pipe, faults=faults
        )
        servo_port, board_port = InProcessPort(bus), pipe
        if hook is not None:
            # in-process a reply is there at once or never: with injected packet loss, do not
            # spin 20 ms of wall time per lost reply (simulated time is not affected)
            servo_port.reply_timeout_ms = 1.0
    if hook is not None:
        hook.attach(clock, bus, board, world)
    try:
        yield bus, board, servo_port, board_port
    finally:
        if hook is not None:
            hook.detach()
        board.stop()
        bus.close()  # no-op on the fast path (no pty)


def run_sim_trial(
    spec: TrialSpec,
    scene: SceneConfig,
    stack: StackConfig,
    *,
    transport: Transport = "fast",
    log_dir: Path | None = None,
    keep_series: bool = False,
    hook: EmulatorHook | None = None,
) -> TrialOutcome:
    """Run one simulated trial end to end and estimate the modulus from it."""
    c = scene.campaign
    geo = trial_geometry(stack, spec)
    retract = geo.contact_translation - c.standoff_mm * 1e-3 - 1e-3
    stack = trial_stack(scene, stack, geo, retract)
    plan = trial_plan(c, stack, roll=geo.plan_roll, contact=geo.contact_translation, home=retract)
    clock = VirtualClock()
    servos = ServoJoints(stack)
    world = trial_world(spec, scene, stack, geo, servos)
    series: dict[str, list[float]] = {}
    on_tick = _series_recorder(world, series) if keep_series else None
    with _emulators(transport, stack, clock, world, hook) as (bus, board, servo_port, board_port):
        servos.bus = bus
        driver = DynamixelBus.from_config(_reply_timeout(stack, transport, hook), port=servo_port)
        reader = FrameReader.from_config(board_port, stack.sensor, stack.board, clock=clock)
        settings = _rig_settings(
            spec, scene, stack, fast_faults=hook is not None and transport == "fast"
        )
        # the rig waits each tick for exactly what the board has sent, never for a frame not sent
        settings = dataclasses.replace(settings, sent_bytes=lambda: board.stats.bytes_sent)
        with DriveController(driver, stack.drive) as drive, reader:
            board.start()
            rig = ServoFbgRig(drive, reader, StrainChain.from_config(stack.fbg), clock, settings)
            chain = rig.zero()
            with _trial_log(log_dir, spec, scene, stack, plan, geo, hook) as log:
                guards = guards_for(c, stack, rig.tick)
                detector = detector_for(c, chain)
                result = run_trial(rig, clock, plan, guards, detector, log, on_tick=on_tick)
                estimate = _estimate(result, spec, scene, stack, geo)
                if log is not None:
                    log.write(estimate_record(estimate))
                    log.write(end_record(result))
    log_path = None if log is None else str(log.path)
    return _outcome(spec, geo, result, estimate, log_path, series)


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


@contextlib.contextmanager
def _trial_log(
    log_dir: Path | None,
    spec: TrialSpec,
    scene: SceneConfig,
    stack: StackConfig,
    plan: TrialPlan,
    geo: TrialGeometry,
    hook: EmulatorHook | None,
) -> Iterator[TrialLogWriter | None]:
    """The trial's log in ``log_dir`` (None: no log), closed however the trial ends."""
    if log_dir is None:
        yield None
        return
    header = _header(spec, scene, stack, plan, geo)
    with TrialLogWriter(log_dir / f"{spec.trial_id}.jsonl", header) as log:
        if hook is not None:
            hook.log_opened(log)
        yield log


def _estimate(
    result: TrialResult, spec: TrialSpec, scene: SceneConfig, stack: StackConfig, geo: TrialGeometry
) -> TrialEstimate:
    flush = stack.tube(spec.tube).flush_translation if spec.kind == "robot" else 0.0
    return estimate_trial(
        result,
        kind=spec.kind,
        exposed_length=spec.exposed_length,
        flush_translation=flush,
        stack=stack,
        section=sensor_section(stack),
        poisson=trial_sample(scene, spec).poisson,
        inputs=_estimator_inputs(spec, scene, stack, geo),
    )


def _outcome(
    spec: TrialSpec,
    geo: TrialGeometry,
    result: TrialResult,
    estimate: TrialEstimate,
    log_path: str | None,
    series: dict[str, list[float]],
) -> TrialOutcome:
    return TrialOutcome(
        spec=spec,
        state=result.state.value,
        reason=result.reason,
        estimate=estimate.paper,
        exposed_length_at_buckling=estimate.exposed_length_at_buckling,
        ik_residual=geo.residual,
        ticks=result.ticks,
        sim_time=result.duration,
        log_path=log_path,
        series=series,
        marks=result.marks,
        joint=estimate.joint,
        joint_seconds=estimate.joint_seconds,
    )


def _header(
    spec: TrialSpec,
    scene: SceneConfig,
    stack: StackConfig,
    plan: TrialPlan,
    geo: TrialGeometry,
) -> dict[str, Any]:
    tube = stack.tube(geo.tube) if spec.kind == "robot" else None
    inputs = _estimator_inputs(spec, scene, stack, geo)
    return {
        "trial": spec.trial_id,
        "source": "simulation",
        "spec": dataclasses.asdict(spec),
        "scene": scene.name,
        **header_common(plan, sensor_section(stack), stack.sensor, tube, spec.poisson, inputs),
    }


def _estimator_inputs(
    spec: TrialSpec, scene: SceneConfig, stack: StackConfig, geo: TrialGeometry
) -> EstimatorInputs:
    """What the joint fit is told: the sample as the user knows it (not the sim's switches)."""
    sample = trial_sample(scene, spec)
    return EstimatorInputs(
        kind=spec.kind,
        exposed_length=spec.exposed_length,
        flush_translation=stack.tube(geo.tube).flush_translation if spec.kind == "robot" else 0.0,
        tip_radius=stack.sensor.tip_radius,
        poisson=sample.poisson,
        thickness=sample.thickness,
        bonded=sample.bonded,
        encoder_resolution=stack.drive.lead / TICKS_PER_REV,
        misalignment=geo.residual,
    )
