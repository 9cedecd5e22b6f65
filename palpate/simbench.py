"""A simulated bench to drive through the hardware path: both emulators and a world with tissue.

``palpate teleop`` runs on it when no port is given, and the tests of ``palpate trial`` and
``palpate teleop`` point the hardware code (:mod:`palpate.hardware`) at it. The servo emulator
and the board emulator sit on pseudo-terminals (``wire=True``: the hardware path byte for byte)
or on in-process transports; time is a :class:`sim.clock.VirtualClock` (tests) or wall time
(interactive). The board's samples come from a :class:`sim.world.World`: the sensor placed by
the forward kinematics of the *mounted* tube (:attr:`SimulatedBench.tube`, which an operator may
change) at the joints the servos are at, pressing on a scene's tissue sample.

A world remembers one touch (its contact table is solved for the exposed length at first
contact), so once the sensor has left the surface the next sample starts a fresh world: the next
touch may come with another tube, roll or exposed length.
"""

from __future__ import annotations

from typing import Any, Self

import numpy as np

from config.scene import SceneConfig
from config.schema import StackConfig, TubeConfig
from palpate.simworld import tissue_model
from robot import kinematics
from robot.drive import INNER_ROLL, OUTER_ROLL, TRANSLATION, RollerGearDrive
from robot.dynamixel.units import rad_from_ticks
from robot.trial.setup import sensor_section
from sensor.reader import layout_from_config
from sim.board import BoardEmulator, BoardSample
from sim.clock import VirtualClock
from sim.dynamixel.bus import EmulatedBus
from sim.inprocess import InProcessPort, MemorySerial
from sim.sample_law import relaxation
from sim.world import Surface, World
from wire.dynamixel import TICKS_PER_REV


def surface_at(tube: TubeConfig, roll: float, translation: float, tip_radius: float) -> Surface:
    """A flat sample that the tip sphere touches head-on at this pose (roll rad, translation m)."""
    pose = kinematics.forward(tube, roll, translation)
    return Surface(point=pose.sensor_tip + tip_radius * pose.tangent, normal=-pose.tangent)


def facing_surface(stack: StackConfig, exposed_length: float) -> Surface:
    """The default sample: facing the first straight tube (else the first tube) at roll 0, where
    the sensor touches it with ``exposed_length`` out; every tube and roll can reach it."""
    tube = next((t for t in stack.tubes if t.tip_angle_deg == 0), stack.tubes[0])
    return surface_at(tube, 0.0, tube.flush_translation + exposed_length, stack.sensor.tip_radius)


class SimulatedBench:
    """Emulated servos and board over a world; a context manager (``start`` / ``close``).

    ``servo_port`` and ``board_port`` are what :func:`palpate.hardware.open_hardware` takes:
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
    ) -> None:
        names = [s.name for s in scene.samples]
        if not names:
            raise ValueError(f"scene {scene.name!r} has no tissue sample")
        chosen = sample if sample is not None else names[0]
        if chosen not in names:
            raise ValueError(f"--sample: no sample {chosen!r} in scene {scene.name!r}; {names}")
        self.stack = stack
        self.scene = scene
        self.sample = next(s for s in scene.samples if s.name == chosen)
        self.surface = surface or facing_surface(stack, scene.campaign.exposed_length_mm * 1e-3)
        self.tube = stack.tube(tube) if tube is not None else stack.tubes[0]
        self._tissue = tissue_model(self.sample, scene.fidelity, stack.sensor.tip_radius)
        self._section = sensor_section(stack)
        self._rng = np.random.default_rng(seed)
        self._truth = RollerGearDrive(stack.drive)  # the servos power up at the home pose
        self._ids = {
            OUTER_ROLL: stack.servos.outer_roll.id,
            INNER_ROLL: stack.servos.inner_roll.id,
            TRANSLATION: stack.servos.translation.id,
        }
        self.bus = EmulatedBus.from_config(stack.servos, clock=clock)
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
        """The emulated servo of a drive joint (``"translation"``, ``"outer_roll"``, ...)."""
        return self.bus.servo(self._ids[name])

    def _joints(self) -> tuple[float, float, int]:
        ticks = {n: self.bus.servo(i).position_ticks for n, i in self._ids.items()}
        q = self._truth.joints({n: rad_from_ticks(t) for n, t in ticks.items()})
        return q.roll, q.translation, ticks[TRANSLATION]

    def _pose(self, roll: float, translation: float) -> tuple[Any, Any, float]:
        p = kinematics.forward(self.tube, roll, translation)
        return p.tube_tip, p.tangent, p.exposed_length

    def _new_world(self) -> World:
        return World(
            section=self._section,
            sensor=self.stack.sensor,
            fbg=self.stack.fbg,
            fidelity=self.scene.fidelity,
            tissue=self._tissue,
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
        world = self._world
        sample = world.sample(t)
        last = world.last
        if last is not None and last.past_contact > 0.0:
            self._touched = True
        elif self._touched:
            self._world, self._touched = self._new_world(), False
        return sample

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
