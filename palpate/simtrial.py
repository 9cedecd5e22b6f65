"""One simulated trial, wired exactly like the bench: emulators in, control stack on top.

The world (``sim.world``) feeds the servo emulator and the board emulator on one virtual clock;
the control stack drives the servos through dynamixel-sdk and reads FBG frames through the frame
reader, then the paper's estimator runs on the trial's marks. ``transport="wire"`` puts both
emulators on pseudo-terminals; ``"fast"`` keeps the same SDK, driver, reader and parser and only
replaces the ptys by in-process transports (``sim.inprocess``).
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, Protocol

import numpy as np

from config.scene import FidelityConfig, SampleConfig, SceneConfig
from config.schema import ServoBusConfig, StackConfig
from estimation.beam import Beam
from estimation.jointfit import JointFit
from estimation.section import Section
from estimation.stiffness import StiffnessEstimate, paper_estimate
from palpate.estimates import EstimatorInputs, joint_estimate, joint_record, loading_rows
from palpate.trialsetup import (
    detector_for,
    guards_for,
    position_tolerance,
    rig_settings,
    sensor_section,
)
from robot import kinematics
from robot.drive import TRANSLATION, DriveController, RollerGearDrive
from robot.dynamixel.driver import DynamixelBus
from robot.dynamixel.units import rad_from_ticks
from robot.indentation import State, TrialMarks, TrialPlan
from robot.rig import ServoFbgRig
from robot.trial import TrialResult, end_record, run_trial
from robot.triallog import TrialLogWriter
from sensor.reader import FrameReader, layout_from_config
from sensor.strain import StrainChain, grating_intervals
from sim.board import BoardEmulator, BoardFaults
from sim.clock import VirtualClock
from sim.dynamixel.bus import EmulatedBus
from sim.inprocess import InProcessPort, MemorySerial
from sim.tissue import TissueModel
from sim.world import Surface, World
from wire.dynamixel import TICKS_PER_REV

Transport = Literal["fast", "wire"]
BENCH_CONTACT_TRANSLATION = 10e-3  # m: where the bench stage touches the sample
VERTICAL = np.array([0.0, 0.0, -1.0])


@dataclass(frozen=True)
class TrialSpec:
    """One trial of a campaign."""

    trial_id: str
    kind: Literal["bench", "robot"]
    sample: str
    modulus: float  # Pa, the ground truth
    poisson: float
    tube: str
    orientation: str
    roll: float  # rad
    exposed_length: float  # m at contact
    seed: int


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
    joint: JointFit | None = None  # the contact-point-free estimate (palpate.estimates)
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


def tissue_model(sample: SampleConfig, fidelity: FidelityConfig, tip_radius: float) -> TissueModel:
    """The simulated tissue's force law for a scene's sample and fidelity switches."""
    return TissueModel(
        modulus=sample.modulus,
        poisson=sample.poisson,
        thickness=(
            sample.thickness if (sample.thickness and fidelity.finite_thickness) else math.inf
        ),
        bonded=sample.bonded,
        tip_radius=tip_radius,
        finite_thickness=fidelity.finite_thickness,
        large_indentation=fidelity.large_indentation,
    )


@dataclass(frozen=True)
class _Geometry:
    plan_roll: float
    contact_translation: float
    surface: Surface
    residual: float
    tube: str


def _robot_geometry(stack: StackConfig, spec: TrialSpec) -> _Geometry:
    """Place the sample where the campaign wants it, then let the IK find the way back to it."""
    tube = stack.tube(spec.tube)
    nominal = kinematics.forward(tube, spec.roll, tube.flush_translation + spec.exposed_length)
    r_tip = stack.sensor.tip_radius
    target = nominal.sensor_tip + r_tip * nominal.tangent
    normal = -nominal.tangent
    ik = kinematics.inverse(
        stack.tubes,
        target,
        normal,
        tip_radius=r_tip,
        translation_limits=stack.drive.translation_limits,
        roll_limits=stack.drive.roll_limits,
    )
    if not ik.reachable:
        raise ValueError(f"trial {spec.trial_id}: target not reachable: {ik.reason}")
    surface = Surface(point=target, normal=normal)
    return _Geometry(ik.roll, ik.advance, surface, ik.residual, ik.tube)


def _bench_geometry(stack: StackConfig, spec: TrialSpec) -> _Geometry:
    depth = BENCH_CONTACT_TRANSLATION + spec.exposed_length + stack.sensor.tip_radius
    surface = Surface(point=depth * VERTICAL, normal=-VERTICAL)
    return _Geometry(0.0, BENCH_CONTACT_TRANSLATION, surface, 0.0, "bench-stage")


def trial_geometry(stack: StackConfig, spec: TrialSpec) -> _Geometry:
    """Where the sample is and how the robot reaches it; ValueError if it cannot."""
    return _bench_geometry(stack, spec) if spec.kind == "bench" else _robot_geometry(stack, spec)


def _pose_fn(stack: StackConfig, spec: TrialSpec, tube_name: str) -> Any:
    if spec.kind == "bench":
        length = spec.exposed_length

        def bench_pose(roll: float, translation: float) -> tuple[Any, Any, float]:
            return translation * VERTICAL, VERTICAL, length

        return bench_pose
    tube = stack.tube(tube_name)
    frame_roll = math.nan
    frame = kinematics.forward(tube, 0.0, 0.0)

    def robot_pose(roll: float, translation: float) -> tuple[Any, Any, float]:
        # The tip frame depends on the roll only, which is constant while the stage moves:
        # keep the last one (the board asks for a pose at every sample).
        nonlocal frame, frame_roll
        if roll != frame_roll:
            frame, frame_roll = kinematics.forward(tube, roll, 0.0), roll
        length = exposed_length_at("robot", translation, 0.0, tube.flush_translation)
        return frame.tube_tip, frame.tangent, length

    return robot_pose


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
    drive_cfg = dataclasses.replace(
        stack.drive, home_translation_mm=retract * 1e3, home_roll_deg=math.degrees(geo.plan_roll)
    )
    board_cfg = stack.board
    if scene.board_rate_hz is not None:
        board_cfg = dataclasses.replace(board_cfg, rate_hz=scene.board_rate_hz)
    stack = dataclasses.replace(stack, drive=drive_cfg, board=board_cfg)
    section = sensor_section(stack)
    sample = next(s for s in scene.samples if s.name == spec.sample)
    fid = scene.fidelity
    tissue = tissue_model(sample, fid, stack.sensor.tip_radius)
    rng = np.random.default_rng(spec.seed)
    clock = VirtualClock()
    truth = RollerGearDrive(drive_cfg)  # the servos power up at the home pose (0 ticks)
    pose = _pose_fn(stack, spec, geo.tube)
    servo_ids = {
        "outer_roll": stack.servos.outer_roll.id,
        "inner_roll": stack.servos.inner_roll.id,
        TRANSLATION: stack.servos.translation.id,
    }
    holder: dict[str, EmulatedBus] = {}
    last_ticks: dict[str, int] = {}
    last_joints = (0.0, 0.0, 0)

    def joints() -> tuple[float, float, int]:
        nonlocal last_ticks, last_joints
        bus = holder["bus"]
        ticks = {n: bus.servo(i).position_ticks for n, i in servo_ids.items()}
        if ticks != last_ticks:  # the servos rest for most board samples: keep the last answer
            q = truth.joints({n: rad_from_ticks(t) for n, t in ticks.items()})
            last_ticks, last_joints = ticks, (q.roll, q.translation, ticks[TRANSLATION])
        return last_joints

    world = World(
        section=section,
        sensor=stack.sensor,
        fbg=stack.fbg,
        fidelity=fid,
        tissue=tissue,
        surface=geo.surface,
        pose=pose,
        joints=joints,
        rng=rng,
        has_force=stack.board.has_force,
        length_grows=spec.kind == "robot",
        encoder_step=stack.drive.lead / TICKS_PER_REV,
    )
    tick = 1.0 / scene.control_rate_hz
    plan = TrialPlan(
        roll=geo.plan_roll,
        contact_advance=geo.contact_translation,
        home_advance=retract,
        standoff=c.standoff_mm * 1e-3,
        post_buckling_travel=c.post_buckling_mm * 1e-3,
        approach_speed=c.approach_speed_mm_per_s * 1e-3,
        indent_speed=c.indent_speed_mm_per_s * 1e-3,
        fast_speed=stack.drive.max_speed,
        position_tolerance=position_tolerance(stack),
    )
    guards = guards_for(c, stack, tick)
    log: TrialLogWriter | None = None
    log_path: str | None = None
    series: dict[str, list[float]] = {"advance": [], "force": [], "s1": [], "s2": [], "s3": []}
    with _emulators(transport, stack, clock, world, hook) as (
        bus,
        board,
        servo_port,
        board_port,
    ):
        holder["bus"] = bus
        driver = DynamixelBus.from_config(stack.servos, port=servo_port)
        reader = FrameReader.from_config(board_port, stack.sensor, stack.board, clock=clock)
        settings = rig_settings(
            c, stack, tick, sync_to_clock=True, exposed_length=spec.exposed_length
        )
        if hook is not None and transport == "fast":
            # in-process frames arrive during the clock advance or never: with injected board
            # faults, do not wait 0.2 s of wall time for each lost frame
            settings = dataclasses.replace(settings, frame_wait_s=0.0)
        with DriveController(driver, drive_cfg) as drive, reader:
            board.start()
            rig = ServoFbgRig(drive, reader, StrainChain.from_config(stack.fbg), clock, settings)
            chain = rig.zero()
            if log_dir is not None:
                path = log_dir / f"{spec.trial_id}.jsonl"
                log_path = str(path)
                log = TrialLogWriter(path, _header(spec, scene, stack, plan, section, geo))
                if hook is not None:
                    hook.log_opened(log)
            on_tick = None
            if keep_series:

                def on_tick(obs: Any, state: State) -> None:
                    st = world.last
                    series["advance"].append(obs.advance)
                    series["force"].append(st.P if st else 0.0)
                    for k, s in zip(("s1", "s2", "s3"), obs.strains, strict=False):
                        series[k].append(s)

            try:
                result = run_trial(
                    rig,
                    clock,
                    plan,
                    guards,
                    detector_for(c, chain),
                    log,
                    on_tick=on_tick,
                )
                estimate, l_b = _estimate(result, spec, stack, section, sample.poisson)
                fit_start = time.perf_counter()
                joint = joint_from_rows(
                    result.record, _estimator_inputs(spec, scene, stack, geo), stack, section
                )
                joint_seconds = time.perf_counter() - fit_start
                if log is not None:
                    log.write(estimate_record(estimate, l_b, joint))
                    log.write(end_record(result))
            finally:
                if log is not None:
                    log.close()
    return TrialOutcome(
        spec=spec,
        state=result.state.value,
        reason=result.reason,
        estimate=estimate,
        exposed_length_at_buckling=l_b,
        ik_residual=geo.residual,
        ticks=result.ticks,
        sim_time=result.duration,
        log_path=log_path,
        series=series if keep_series else {},
        marks=result.marks,
        joint=joint,
        joint_seconds=joint_seconds,
    )


def exposed_length_at(kind: str, x: float, fixed_length: float, flush_translation: float) -> float:
    """Exposed length (m) at stage position ``x``: fixed on the bench, on the robot the stage
    translation past the tube's flush translation. Shared by the trial and ``palpate replay``."""
    if kind == "bench":
        return fixed_length
    return x - flush_translation


def estimate_from_marks(
    x_contact: float | None,
    x_buckling: float | None,
    strains: tuple[float, ...],
    length: float | None,
    stack: StackConfig,
    section: Section,
    poisson: float,
) -> StiffnessEstimate | None:
    """The paper's estimate: delta from the encoder (Eq. 14), P from the FBG-fitted elastica at
    the exposed length at buckling (Eq. 7; P_cr when the fit fails), E from Hertz (Eq. 13)."""
    if x_contact is None or x_buckling is None or length is None:
        return None
    beam = Beam.from_section(section, length)
    P: float | None = None
    if strains:
        fit = beam.fit_strains(np.asarray(strains), grating_intervals(stack.sensor, length))
        if fit.success and fit.P > 0:
            P = float(fit.P)
    return paper_estimate(
        x_contact, x_buckling, length, section, stack.sensor.tip_radius, poisson, P=P
    )


def _estimate(
    result: TrialResult, spec: TrialSpec, stack: StackConfig, section: Section, poisson: float
) -> tuple[StiffnessEstimate | None, float | None]:
    m = result.marks
    if m.x_buckling is None:
        return None, None
    flush = stack.tube(spec.tube).flush_translation if spec.kind == "robot" else 0.0
    length = exposed_length_at(spec.kind, m.x_buckling, spec.exposed_length, flush)
    est = estimate_from_marks(
        m.x_contact, m.x_buckling, m.strains_at_buckling, length, stack, section, poisson
    )
    return est, length


def _header(
    spec: TrialSpec,
    scene: SceneConfig,
    stack: StackConfig,
    plan: TrialPlan,
    section: Section,
    geo: _Geometry,
) -> dict[str, Any]:
    return {
        "trial": spec.trial_id,
        "source": "simulation",
        "spec": dataclasses.asdict(spec),
        "scene": scene.name,
        "plan": dataclasses.asdict(plan),
        "section": dataclasses.asdict(section),
        "sensor": dataclasses.asdict(stack.sensor),
        "tube": dataclasses.asdict(stack.tube(geo.tube)) if spec.kind == "robot" else None,
        "poisson": spec.poisson,
        "estimator": _estimator_inputs(spec, scene, stack, geo).as_dict(),
        "units": "SI (m, N, Pa, rad, s); strains dimensionless",
    }


def _estimator_inputs(
    spec: TrialSpec, scene: SceneConfig, stack: StackConfig, geo: _Geometry
) -> EstimatorInputs:
    """What the joint fit is told: the sample as the user knows it (not the sim's switches)."""
    sample = next(s for s in scene.samples if s.name == spec.sample)
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


def joint_from_rows(
    rows: Any, inputs: EstimatorInputs, stack: StackConfig, section: Section
) -> JointFit:
    """The joint fit from (state, advance, strains) rows: the trial's record or a log's samples."""
    advance, strains = loading_rows(rows, len(stack.sensor.used_gratings))
    return joint_estimate(advance, strains, inputs, stack.sensor, section)


def estimate_record(
    est: StiffnessEstimate | None, length: float | None, joint: JointFit | None = None
) -> dict[str, Any]:
    if est is None:
        return {
            "kind": "estimate",
            "success": False,
            "message": "no buckling detected",
            "joint": joint_record(joint),
        }
    return {
        "kind": "estimate",
        "success": est.success,
        "modulus": est.modulus,
        "delta": est.delta,
        "force": est.force,
        "exposed_length": length,
        "message": est.message,
        "joint": joint_record(joint),
    }
