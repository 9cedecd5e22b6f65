"""What one simulated trial is and the world it runs in.

:class:`TrialSpec` is one trial of a campaign; :func:`trial_geometry` places its sample where the
campaign wants it and finds how the robot reaches it (inverse kinematics on the robot, a fixed
stage on the bench); :func:`trial_world` builds the ``sim.world`` of the trial: the tissue
(:func:`tissue_model`), the sensor's pose from the joints, and the joints themselves, read off
the emulated servos' encoders (:class:`ServoJoints`). ``palpate.simulation.trial`` wires it to the
emulators and the control stack.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from palpate.config.loader import InputError
from palpate.config.sample import SampleConfig
from palpate.config.scene import FidelityConfig, SceneConfig
from palpate.config.schema import StackConfig, TubeConfig
from palpate.estimation.beam.stage import Stage
from palpate.robot import kinematics
from palpate.robot.drive import TRANSLATION, RollerGearDrive
from palpate.robot.dynamixel.units import rad_from_ticks
from palpate.robot.trial.setup import sensor_section
from palpate.sim.dynamixel.bus import EmulatedBus
from palpate.sim.equilibrium import TissueLaw
from palpate.sim.gravity import BeamWeight
from palpate.sim.sample_law import describe, relaxation, world_tissue
from palpate.sim.world import Surface, World
from palpate.simulation.placement import place_sample
from palpate.wire.dynamixel import TICKS_PER_REV

BENCH_CONTACT_TRANSLATION = 10e-3  # m: where the bench stage touches the sample
# the bench's column as a trial's tube: a straight stage ("straight" in the trials' ids)
BENCH_COLUMN = TubeConfig(name="straight")
VERTICAL = np.array([0.0, 0.0, -1.0])


@dataclass(frozen=True)
class TrialSpec:
    """One trial of a campaign; ``tube`` is the robot's tube it runs on (on the bench,
    :data:`BENCH_COLUMN`)."""

    trial_id: str
    kind: Literal["bench", "robot"]
    sample: str
    modulus: float  # Pa, the ground truth
    poisson: float
    tube: TubeConfig
    orientation: str
    roll: float  # rad
    exposed_length: float  # m at contact
    seed: int
    reference: float | None = None  # Pa, the reported reference modulus; None: the truth
    indent_speed: float | None = None  # m/s; None: the campaign's indent_speed_mm_per_s
    at: tuple[float, float] = (0.0, 0.0)  # m: the point of the sample's surface it presses
    # The tissue's outward unit normal in the robot's frame where the planned tip meets it (a
    # robot trial placed on a surface that faces a known way: a map through the robot), None:
    # facing the tube, then tilted as the sample says. The controller is told none of it.
    facing: tuple[float, float, float] | None = None

    @property
    def stage(self) -> Stage:
        """The stage this trial advances on: the bench column, or its tube."""
        return Stage.of_tube(self.kind, self.tube, self.exposed_length)

    def record(self) -> dict[str, Any]:
        """The spec as a log's header writes it (its tube by name)."""
        record = {**dataclasses.asdict(self), "tube": self.tube.name}
        if self.facing is None:
            del record["facing"]  # the logs of trials that face their tube, as they were
        return record

    @property
    def reported(self) -> float:
        """The modulus the lab reports for the sample (Pa): what the paper's tables compare
        against. The world's truth is ``modulus``."""
        return self.modulus if self.reference is None else self.reference


def tissue_model(
    sample: SampleConfig,
    fidelity: FidelityConfig,
    tip_radius: float,
    at: tuple[float, float] = (0.0, 0.0),
) -> TissueLaw:
    """The simulated tissue's force law for a scene's sample and fidelity switches
    (``sim.sample_law``: the finite-element table or the closed forms; the instantaneous law
    of a viscoelastic sample), the tip pressing at ``at`` (m) of the sample."""
    return world_tissue(sample, fidelity, tip_radius, at)


def tissue_description(scene: SceneConfig, stack: StackConfig, sample: str) -> dict[str, Any]:
    """What the world's tissue of the scene's ``sample`` is (``tissue_model`` in results)."""
    s = next(x for x in scene.samples if x.name == sample)
    return describe(s, scene.fidelity, stack.sensor.tip_radius)


@dataclass(frozen=True)
class TrialGeometry:
    """Where a trial's sample is and how the robot reaches it (SI: rad, m): the planned roll and
    contact translation, the sample's surface, the IK's residual angle and the tube it chose."""

    plan_roll: float
    contact_translation: float
    surface: Surface
    residual: float
    tube: str


def _robot_geometry(
    stack: StackConfig, spec: TrialSpec, sample: SampleConfig | None
) -> TrialGeometry:
    """Plan the trial where the campaign aims it (the IK on the surface the plan believes in:
    facing the tube at the target), and place the sample there as the scene says
    (:func:`palpate.simulation.placement.place_sample`: tilted, moved, curved)."""
    tube = spec.tube
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
        raise InputError(f"trial {spec.trial_id}: target not reachable: {ik.reason}")
    if spec.facing is not None:
        n = np.asarray(spec.facing, dtype=np.float64)  # the tip sphere touches it at -R n
        radius = None if sample is None else sample.curvature_radius  # a dome's
        surface = Surface(point=nominal.sensor_tip - r_tip * n, normal=n, radius=radius)
    elif sample is None:
        surface = Surface(point=target, normal=normal)
    else:
        surface = place_sample(tube, spec.roll, (target, nominal.tangent), sample, spec.seed)
    return TrialGeometry(ik.roll, ik.advance, surface, ik.residual, ik.tube)


def _bench_geometry(
    stack: StackConfig, spec: TrialSpec, sample: SampleConfig | None
) -> TrialGeometry:
    """The vertical stage: the sample under it, tilted as the scene says (the stage cannot turn
    to meet it: the tilt is the trial's misalignment)."""
    depth = BENCH_CONTACT_TRANSLATION + spec.exposed_length + stack.sensor.tip_radius
    surface = Surface(point=depth * VERTICAL, normal=-VERTICAL)
    if sample is not None and (sample.tilt != 0.0 or sample.curvature_radius is not None):
        nominal = (surface.point, VERTICAL)  # the column, a straight "tube": azimuth from -y
        surface = place_sample(BENCH_COLUMN, -math.pi / 2, nominal, sample, spec.seed)
    return TrialGeometry(0.0, BENCH_CONTACT_TRANSLATION, surface, 0.0, "bench-stage")


def trial_geometry(
    stack: StackConfig, spec: TrialSpec, sample: SampleConfig | None = None
) -> TrialGeometry:
    """Where the sample is and how the robot reaches it; ValueError if it cannot. ``sample``:
    the scene's, for its pose (None: the plan's surface, facing the tube at the target)."""
    if spec.stage.tube is None:
        return _bench_geometry(stack, spec, sample)
    return _robot_geometry(stack, spec, sample)


def _pose_fn(stack: StackConfig, spec: TrialSpec, tube_name: str) -> Any:
    stage = spec.stage
    if stage.tube is None:
        length = stage.exposed

        def bench_pose(roll: float, translation: float) -> tuple[Any, Any, float]:
            return translation * VERTICAL, VERTICAL, length

        return bench_pose
    tube = stack.tube(tube_name)  # the tube the inverse kinematics picked
    on_tube = Stage.on(tube, stage.exposed)
    frame_roll = math.nan
    frame = kinematics.forward(tube, 0.0, 0.0)

    def robot_pose(roll: float, translation: float) -> tuple[Any, Any, float]:
        # The tip frame depends on the roll only, which is constant while the stage moves:
        # keep the last one (the board asks for a pose at every sample).
        nonlocal frame, frame_roll
        if roll != frame_roll:
            frame, frame_roll = kinematics.forward(tube, roll, 0.0), roll
        return frame.tube_tip, frame.tangent, on_tube.exposed_length(translation)

    return robot_pose


def trial_stack(
    scene: SceneConfig, stack: StackConfig, geo: TrialGeometry, retract: float
) -> StackConfig:
    """The robot as this trial runs it: its servos power up at the trial's home pose (retracted
    by ``retract``, m, at the planned roll) and the board streams at the scene's rate."""
    drive = dataclasses.replace(
        stack.drive, home_translation_mm=retract * 1e3, home_roll_deg=math.degrees(geo.plan_roll)
    )
    board = stack.board
    if scene.board_rate_hz is not None:
        board = dataclasses.replace(board, rate_hz=scene.board_rate_hz)
    return dataclasses.replace(stack, drive=drive, board=board)


def trial_sample(scene: SceneConfig, spec: TrialSpec) -> SampleConfig:
    """The scene's sample the trial indents."""
    return next(s for s in scene.samples if s.name == spec.sample)


class ServoJoints:
    """The stage's true joints read off the emulated servos' encoders (the world's ``joints``):
    (roll rad, translation m, translation encoder ticks). ``bus`` is set once the emulators run."""

    def __init__(self, stack: StackConfig) -> None:
        self.bus: EmulatedBus | None = None
        self._truth = RollerGearDrive(stack.drive)  # the servos power up at the home pose
        self._ids = {
            "outer_roll": stack.servos.outer_roll.id,
            "inner_roll": stack.servos.inner_roll.id,
            TRANSLATION: stack.servos.translation.id,
        }
        self._last_ticks: dict[str, int] = {}
        self._last: tuple[float, float, int] = (0.0, 0.0, 0)

    def read(self) -> tuple[float, float, int]:
        if self.bus is None:
            raise RuntimeError("the world read the servos before the emulated bus was started")
        ticks = {n: self.bus.servo(i).position_ticks for n, i in self._ids.items()}
        if ticks != self._last_ticks:  # the servos rest for most board samples: keep the last
            q = self._truth.joints({n: rad_from_ticks(t) for n, t in ticks.items()})
            self._last_ticks, self._last = ticks, (q.roll, q.translation, ticks[TRANSLATION])
        return self._last


def trial_world(
    spec: TrialSpec, scene: SceneConfig, stack: StackConfig, geo: TrialGeometry, servos: ServoJoints
) -> World:
    """The simulated world of one trial: the scene's sample at the trial's surface, seeded."""
    sample = trial_sample(scene, spec)
    sensor = stack.sensor
    weight = BeamWeight.of(sensor.tip_mass, sensor.linear_mass) if scene.fidelity.gravity else None
    return World(
        section=sensor_section(stack),
        sensor=stack.sensor,
        fbg=stack.fbg,
        fidelity=scene.fidelity,
        tissue=tissue_model(sample, scene.fidelity, stack.sensor.tip_radius, spec.at),
        surface=geo.surface,
        pose=_pose_fn(stack, spec, geo.tube),
        joints=servos.read,
        rng=np.random.default_rng(spec.seed),
        has_force=stack.board.has_force,
        length_grows=spec.stage.grows,
        encoder_step=stack.drive.lead / TICKS_PER_REV,
        relaxation=relaxation(sample, scene.fidelity),
        friction=sample.friction,
        poisson=sample.poisson,
        weight=weight,
    )
