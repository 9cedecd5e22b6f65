"""A simulated bench to drive through the hardware path: both emulators and a world with tissue.

``palpate teleop`` runs on it when no port is given, and the tests of ``palpate trial`` and
``palpate teleop`` point the hardware code (:mod:`palpate.lab.hardware`) at it. The servo emulator
and the board emulator sit on pseudo-terminals (``wire=True``: the hardware path byte for byte)
or on in-process transports; time is a :class:`sim.clock.VirtualClock` (tests) or wall time
(interactive). The board's samples come from a :class:`sim.world.World`: the sensor placed by
the forward kinematics of the *mounted* tube (:attr:`SimulatedBench.tube`, which an operator may
change) at the joints the servos are at, pressing on a scene's tissue sample.

A world remembers one touch (its contact table is solved for the exposed length at first
contact), so once the sensor has left the surface the next sample starts a fresh world: the next
touch may come with another tube, roll or exposed length.

Several samples may stand in front of the robot (:class:`Station` s, e.g. one per stored pose
of a bench file, :func:`stations_for`, which ``palpate emulate --scene`` uses): while the sensor
is free, the station whose roll is nearest the robot's is the one in front of it (its sample,
surface and tube: the operator mounts the tube the pose names).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Self

import numpy as np

from palpate.config.bench import LoadedBench
from palpate.config.loader import ConfigError, InputError
from palpate.config.sample import SampleConfig
from palpate.config.scene import SceneConfig
from palpate.config.schema import MM, StackConfig, TubeConfig, servo_roster
from palpate.config.targets import load_targets
from palpate.config.xystage import XYStageConfig
from palpate.robot import kinematics
from palpate.robot.drive import SERVOS, TRANSLATION, RollerGearDrive
from palpate.robot.dynamixel.units import rad_from_ticks
from palpate.robot.trial.setup import sensor_section
from palpate.robot.xystage import STAGE_SERVOS, Gantry, XYAxes
from palpate.sensor.parser import layout_from_config
from palpate.sim.board import BoardEmulator, BoardSample
from palpate.sim.clock import VirtualClock
from palpate.sim.dynamixel.bus import EmulatedBus
from palpate.sim.inprocess import InProcessPort, MemorySerial
from palpate.sim.sample_law import relaxation
from palpate.sim.world import Surface, World
from palpate.simulation.world import tissue_model
from palpate.wire.dynamixel import TICKS_PER_REV


def surface_at(tube: TubeConfig, roll: float, translation: float, tip_radius: float) -> Surface:
    """A flat sample that the tip sphere touches head-on at this pose (roll rad, translation m)."""
    pose = kinematics.forward(tube, roll, translation)
    return Surface(point=pose.sensor_tip + tip_radius * pose.tangent, normal=-pose.tangent)


def facing_surface(stack: StackConfig, exposed_length: float) -> Surface:
    """The default sample: facing the first straight tube (else the first tube) at roll 0, where
    the sensor touches it with ``exposed_length`` out; every tube and roll can reach it."""
    tube = next((t for t in stack.tubes if t.tip_angle_deg == 0), stack.tubes[0])
    return surface_at(tube, 0.0, tube.flush_translation + exposed_length, stack.sensor.tip_radius)


def carried_touch(
    base: Any, normal: Any, roll: float, tube: TubeConfig, cfg: XYStageConfig
) -> tuple[float, float]:
    """The point of a plane tissue (outward ``normal``) the tip presses with the robot's base
    moved by ``base`` (m) from where it pressed the plane's origin: the sensor's line moved by
    ``base`` meets the plane there, read along the stage's two directions. (x, y) itself when
    the directions lie in the plane."""
    t = kinematics.tangent(tube, roll)
    n = np.asarray(normal)
    moved = base - (float(base @ n) / float(t @ n)) * t
    return float(moved @ np.asarray(cfg.x_direction)), float(moved @ np.asarray(cfg.y_direction))


@dataclass(frozen=True)
class Station:
    """A sample in front of the emulated robot: the scene sample's name, its surface, and the
    tube mounted (by name) when the robot reaches it at ``roll`` (rad)."""

    sample: str
    surface: Surface
    tube: str
    roll: float = 0.0


def stations_for(scene: SceneConfig, loaded: LoadedBench) -> list[Station]:
    """A station per distinct stored pose of the bench file's trials: the scene's sample the
    trial names (its ``sample`` label), else the scene's rigid reference for a ``rigid`` trial,
    else the scene's first sample; its surface where the pose expects contact (the stand-off
    pose plus ``campaign.standoff_mm``), facing the sensor head-on.

    Raises:
        ConfigError: a trial's target is not in the targets file.
    """
    stack, bench = loaded.stack, loaded.bench
    stored = {t.name: t for t in load_targets(loaded.targets_path).targets}
    stations: dict[str, Station] = {}
    for i, entry in enumerate(bench.trials):
        target = stored.get(entry.target)
        if target is None:
            raise ConfigError(
                str(loaded.path), f"trials[{i}].target", f"no target {entry.target!r}"
            )
        if target.name in stations:
            continue
        sample = _scene_sample(scene, entry.sample, entry.rigid)
        contact = target.translation + bench.campaign.standoff_mm * MM
        surface = surface_at(stack.tube(target.tube), target.roll, contact, stack.sensor.tip_radius)
        stations[target.name] = Station(sample.name, surface, target.tube, target.roll)
    return list(stations.values())


def _scene_sample(scene: SceneConfig, label: str, rigid: bool) -> SampleConfig:
    named = [s for s in scene.samples if s.name == label]
    if named:
        return named[0]
    if rigid:
        refs = [s for s in scene.samples if s.rigid]
        if refs:
            return refs[0]
    return scene.samples[0]


class SimulatedBench:
    """Emulated servos and board over a world; a context manager (``start`` / ``close``).

    ``servo_port`` and ``board_port`` are what :func:`palpate.lab.hardware.open_hardware` takes:
    pty paths with ``wire=True``, in-process transports otherwise.
    """

    def __init__(
        self,
        stack: StackConfig,
        scene: SceneConfig,
        *,
        sample: str | None = None,
        surface: Surface | None = None,
        tube: str | None = None,
        clock: VirtualClock | None = None,
        wire: bool = True,
        seed: int = 0,
        stations: Sequence[Station] | None = None,
    ) -> None:
        names = [s.name for s in scene.samples]
        if not names:
            raise ValueError(f"scene {scene.name!r} has no tissue sample")
        chosen = sample if sample is not None else names[0]
        if chosen not in names:
            raise InputError(f"--sample: no sample {chosen!r} in scene {scene.name!r}; {names}")
        self.stack = stack
        self.scene = scene
        if not stations:
            place = surface or facing_surface(stack, scene.campaign.exposed_length)
            stations = [Station(chosen, place, tube or stack.tubes[0].name)]
        self.stations = list(stations)
        self._station = 0
        self.sample = self._sample_config(self.stations[0].sample)
        self.surface = self.stations[0].surface
        self.tube = stack.tube(self.stations[0].tube)
        self._section = sensor_section(stack)
        self._rng = np.random.default_rng(seed)
        self._truth = RollerGearDrive(stack.drive)  # the servos power up at the home pose
        self._ids = {n: s.id for n, s in servo_roster(stack.servos, stack.stage).items()}
        self.bus = EmulatedBus.from_config(stack.servos, clock=clock, stage=stack.stage)
        self._stage = None if stack.stage is None else XYAxes(stack.stage)  # home at power-up
        self._gantry = Gantry.of(stack.stage)  # a stage that carries the robot, not the sample
        self._placed = self._stage_at()  # where the stage stood when the world was made (m)
        self._base = np.zeros(3)  # the robot's base frame, moved by a stage that carries it (m)
        self.at = self._placed  # the point of the sample under the tip (m)
        self._world = self._new_world()
        self._touched = False
        layout = layout_from_config(stack.sensor, stack.board)
        rate = stack.board.rate_hz
        self.servo_port: Any
        self.board_port: Any
        if wire:
            self.board = BoardEmulator(self._sample, layout, rate_hz=rate, clock=clock)
            self.servo_port = self.bus.open()
            self.board_port = self.board.port
        else:
            pipe = MemorySerial()
            self.board = BoardEmulator(self._sample, layout, rate_hz=rate, clock=clock, sink=pipe)
            self.servo_port = InProcessPort(self.bus)
            self.board_port = pipe

    @property
    def world(self) -> World:
        return self._world

    def servo(self, name: str) -> Any:
        """The emulated servo of a drive joint (``"translation"``, ``"outer_roll"``, ...) or
        of a stage axis (``"stage_x"``, ``"stage_y"``)."""
        return self.bus.servo(self._ids[name])

    def _joints(self) -> tuple[float, float, int]:
        ticks = {n: self.servo(n).position_ticks for n in SERVOS}
        q = self._truth.joints({n: rad_from_ticks(t) for n, t in ticks.items()})
        return q.roll, q.translation, ticks[TRANSLATION]

    def _stage_at(self) -> tuple[float, float]:
        """Where the x-y stage has the sample under the tip (m; (0, 0) without a stage)."""
        if self._stage is None:
            return (0.0, 0.0)
        return self._stage.position(
            {n: rad_from_ticks(self.servo(n).position_ticks) for n in STAGE_SERVOS}
        )

    def _stage_settled(self) -> bool:
        """The stage stands still somewhere else than the world's point (a move has ended)."""
        if self._stage is None or any(self.servo(n).velocity_ticks_per_s for n in STAGE_SERVOS):
            return False
        at = self._stage_at()
        return max(abs(at[0] - self._placed[0]), abs(at[1] - self._placed[1])) > 1e-6

    def _place(self) -> None:
        """Where the stage now stands: the point of the tissue under the tip (``at``) and, for a
        stage that carries the robot, the base frame's offset."""
        self._placed = self._stage_at()
        if self._gantry is None:
            self.at = self._placed  # the stage slid the sample: the tissue under the tip
            return
        self._base = np.asarray(self._gantry.base(self._placed))
        roll = self._joints()[0]
        self.at = carried_touch(self._base, self.surface.normal, roll, self.tube, self._gantry.cfg)

    def _pose(self, roll: float, translation: float) -> tuple[Any, Any, float]:
        p = kinematics.forward(self.tube, roll, translation)
        return p.tube_tip + self._base, p.tangent, p.exposed_length

    def _sample_config(self, name: str) -> SampleConfig:
        return next(s for s in self.scene.samples if s.name == name)

    def _nearest_station(self) -> int:
        """The station whose roll is nearest the robot's (the first of equals)."""
        if len(self.stations) == 1:
            return 0
        roll = self._joints()[0]
        gaps = [abs(math.remainder(roll - st.roll, math.tau)) for st in self.stations]
        return gaps.index(min(gaps))

    def _new_world(self) -> World:
        return World(
            section=self._section,
            sensor=self.stack.sensor,
            fbg=self.stack.fbg,
            fidelity=self.scene.fidelity,
            tissue=tissue_model(
                self.sample, self.scene.fidelity, self.stack.sensor.tip_radius, self.at
            ),
            surface=self.surface,
            pose=self._pose,
            joints=self._joints,
            rng=self._rng,
            has_force=self.stack.board.has_force,
            relaxation=relaxation(self.sample, self.scene.fidelity),
            length_grows=True,
            encoder_step=self.stack.drive.lead / TICKS_PER_REV,
        )

    def _sample(self, t: float) -> BoardSample:
        if not self._touched and len(self.stations) > 1:
            self._face(self._nearest_station())
        if not self._touched and self._stage_settled():
            self._place()
            self._world = self._new_world()
        world = self._world
        sample = world.sample(t)
        last = world.last
        if last is not None and last.past_contact > 0.0:
            self._touched = True
        elif self._touched:
            self._world, self._touched = self._new_world(), False
        return sample

    def _face(self, k: int) -> None:
        """Put station ``k`` in front of the robot (a fresh world) if it is not already."""
        if k == self._station:
            return
        st = self.stations[k]
        self._station = k
        self.sample = self._sample_config(st.sample)
        self.surface = st.surface
        self.tube = self.stack.tube(st.tube)
        if self._gantry is not None:
            self._place()  # the same base, another surface
        self._world = self._new_world()

    def start(self) -> Self:
        """Solve one contact state first (the mechanics' tables are built on first use, about
        0.4 s), so the first touch does not stall a real-time board stream; then stream."""
        self._world.solve_on_grid(np.linspace(0.0, 1e-5, 3), self.stack.sensor.exposed_length)
        self.board.start()
        return self

    def close(self) -> None:
        self.board.stop()
        self.bus.close()

    def __enter__(self) -> Self:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()
