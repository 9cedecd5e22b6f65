"""The trial rig on real interfaces: servos through the drive, FBG frames through the reader.

:class:`ServoFbgRig` implements :class:`robot.trial.run.Rig` over a
:class:`robot.drive.DriveController` (any :class:`robot.motors.MotorBus`: dynamixel-sdk on a
real port, on the emulator's pty, or on the in-process transport) and a
:class:`sensor.reader.FrameReader` (a real port, a pty, or an in-memory serial object). The
same class runs the bench, the wire simulation and the fast simulation.

Motion is streamed: each tick the rig moves its setpoint toward the state machine's goal by at
most ``speed * tick`` and sends it, so the stage speed is the state machine's, and the servo's own
profile only smooths it.
"""

from __future__ import annotations

import contextlib
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..config.schema import DEFAULT_CONTROL_RATE_HZ, StackConfig
from ..estimation.beam.states import axial_strain
from ..sensor.clock import Clock
from ..sensor.reader import FrameReader, SensorPortError
from ..sensor.strain import StrainChain
from ..sensor.tipforce import TipForceChain, tip_chain
from ..wire.frame import Frame, Status
from .drive import DriveController, JointState
from .indentation import Command, Observation
from .motors import ServoFaultError, ServoTransportError

ContactMode = Literal["event", "fbg", "tip"]
REZERO_FRAMES = 8  # frames a zero taken again during a trial averages


@dataclass(frozen=True)
class RigSettings:
    tick: float = 1.0 / DEFAULT_CONTROL_RATE_HZ  # s, control period (the one place it is kept)
    contact: ContactMode = "event"
    fbg_contact_strain: float = 20e-6  # compressive axial strain P/EA that means contact (FBG)
    # The gratings' onset bending shape (estimation.beam.states.onset_mode) at the exposed length:
    # FBG contact reads the axial strain with the bow of a not-quite-straight beam taken out.
    # None: the mean strain (right for a straight beam only).
    fbg_bending_mode: tuple[float, ...] | None = None
    # Tip contact: the tip grating's load over this many of its standard deviations at rest
    # (the zero's), and at least ``tip_contact_floor`` (N)
    tip_contact_sigmas: float = 5.0
    tip_contact_floor: float = 1e-5
    # Simulation: before using a tick's frames, wait until what the emulator has sent up to the
    # current clock time has come through the transport (``sent_bytes``: the bytes it has put on
    # the wire so far; without it, the frame due by ``frame_period`` after the last one).
    sync_to_clock: bool = False
    sent_bytes: Callable[[], int] | None = None
    frame_period: float = 1e-3  # s between board frames
    frame_wait_s: float = 2.0  # real-time bound on that wait (it never waits for a frame not sent)
    roll_speed: float = math.radians(90.0)  # rad/s for roll goals
    # The servo bus may miss replies (a status packet late or lost: a busy host, noise on the
    # line) for this long (s, the rig's clock) before the rig reports it lost; meanwhile the
    # motion holds (no new goal) and the ticks keep the last joints read, marked stale.
    bus_silence: float = 0.25
    # ... and for at least this many reads in a row (each its own retries): the silence is the
    # bus's, not a host that did not run the rig for a while (a dead bus misses three reads of
    # four 20 ms attempts in about bus_silence anyway).
    bus_missed_reads: int = 3


class ServoFbgRig:
    """A :class:`robot.trial.run.Rig` over a drive and an FBG frame reader."""

    def __init__(
        self,
        drive: DriveController,
        reader: FrameReader,
        chain: StrainChain,
        clock: Clock,
        settings: RigSettings | None = None,
        tip: TipForceChain | None = None,
    ) -> None:
        self.drive = drive
        self.reader = reader
        self.chain = chain
        self.tip = tip
        self.clock = clock
        self.settings = settings or RigSettings()
        self._setpoint: JointState | None = None
        self._joints: JointState | None = None
        self._frame: Frame | None = None
        self._frame_t = -math.inf
        self._twist = 0.0
        self._read_t: float | None = None  # when the servos last answered (the rig's clock)
        self._first_t: float | None = None  # the first tick's time: silence counts from it
        self._stale = False  # the last read was missed: hold the motion
        self.missed_reads = 0  # ticks whose servo read was missed and tolerated
        self._missed_in_row = 0  # reads missed since the servos last answered
        self.frames: list[Frame] = []  # every frame received, for the trial log and plots

    @classmethod
    def for_stack(
        cls,
        drive: DriveController,
        reader: FrameReader,
        stack: StackConfig,
        clock: Clock,
        settings: RigSettings | None = None,
    ) -> ServoFbgRig:
        """The rig of a robot configuration: its strain chain, and its tip grating's if any."""
        tip = tip_chain(stack.sensor.tip_grating, stack.fbg)
        chain = StrainChain.from_config(stack.fbg, stack.sensor.used_gratings)
        return cls(drive, reader, chain, clock, settings, tip)

    @property
    def tick(self) -> float:
        """The control period (s), from the settings."""
        return self.settings.tick

    # -- set-up ------------------------------------------------------------------------------
    def zero(self, samples: int = 20) -> StrainChain:
        """Capture the strain baseline at rest over ``samples`` frames (the sensor is free)."""
        frames: list[Frame] = []
        # Sleep first: a stream that has just started has no frame due yet (and, synchronised
        # to the clock, sleep a frame period at least, so that one is due).
        pause = self.settings.tick
        if self.settings.sync_to_clock:
            pause = max(pause, self.settings.frame_period)
        for _ in range(samples * 10):
            self.clock.sleep(pause)
            frames += self._receive()
            if len(frames) >= samples:
                break
        return self._zero_on(frames)

    def _zero_on(self, frames: list[Frame]) -> StrainChain:
        """The chain zeroed on ``frames`` (taken at rest, the sensor free)."""
        if not frames:
            raise SensorPortError(f"board port {self.reader.port_name!r}: no frames to zero on")
        wl = np.stack([f.wavelengths for f in frames])
        ref = None
        if frames[0].reference is not None:
            ref = np.asarray([f.reference for f in frames], dtype=float)
        self.chain = self.chain.zeroed(wl, ref)
        if self.tip is not None:
            tips = [f.tip for f in frames]
            if any(t is None for t in tips):
                raise SensorPortError(
                    f"board port {self.reader.port_name!r}: the sensor has a tip grating and the "
                    "board's frames carry none (frame protocol revision 1.1, options bit 2)"
                )
            self.tip = self.tip.zeroed(np.asarray(tips, dtype=float), ref)
        return self.chain

    # -- Rig protocol ------------------------------------------------------------------------
    def observe(self, t: float) -> Observation:
        fault: str | None = None
        lost = False
        age = 0.0
        self._first_t = t if self._first_t is None else self._first_t
        try:
            joints, motors = self.drive.read()
            self._joints, self._read_t, self._stale = joints, t, False
            self._missed_in_row = 0
            self._twist = self.drive.drive.twist({n: m.position for n, m in motors.items()})
        except ServoFaultError as exc:
            fault = str(exc)
        except ServoTransportError as exc:
            # A missed reply: tolerated (the motion holds, the joints are the last read, none
            # before the first) while the bus has been silent, since its last answer or the
            # trial's first tick, for less than ``bus_silence`` or fewer than
            # ``bus_missed_reads`` reads in a row; then it is lost.
            since = self._first_t if self._read_t is None else self._read_t
            self._missed_in_row += 1
            silent = t - since >= self.settings.bus_silence
            if silent and self._missed_in_row >= self.settings.bus_missed_reads:
                fault, lost = f"bus transport: {exc} (silent {1e3 * (t - since):.0f} ms)", True
            else:
                age, self._stale = max(t - since, 1e-9), True
                self.missed_reads += 1
        joints = self._joints or JointState(math.nan, math.nan)
        # A lost board port is not an error here: the reader counts it and reopens the port,
        # the stream goes stale, and the state machine's FBG-lost guard decides.
        frames = self._receive()
        if frames:
            self._frame = frames[-1]
            self._frame_t = t
        strains: tuple[float, ...] = ()
        contact = False
        tip_force: float | None = None
        if self._frame is not None:
            f = self._frame
            eps = self.chain.strains(f.wavelengths, reference=f.reference)
            strains = tuple(float(x) for x in eps)
            tip_force = self._tip_force(f)
            contact = self._contact(f, eps, tip_force)
        return Observation(
            t=t,
            advance=joints.translation,
            roll=joints.roll,
            strains=strains,
            contact=contact,
            stream_age=t - self._frame_t,
            servo_fault=fault,
            bus_lost=lost,
            twist=self._twist,
            tip_force=tip_force,
            joints_age=age,
            gate=None if self._frame is None else bool(self._frame.flags & Status.BREATH_HOLD),
            beat=any(f.flags & Status.CARDIAC_TRIGGER for f in frames),
            frame=self._frame,
        )

    def _tip_force(self, f: Frame) -> float | None:
        """The tip grating's load (N) in frame ``f``; None without a tip grating or its zero."""
        if self.tip is None or self.tip.zero is None or f.tip is None:
            return None
        return self.tip.force(f.tip, f.reference)

    def _contact(self, f: Frame, eps: np.ndarray, tip_force: float | None) -> bool:
        """The contact as the settings read it: the rig's event input, the beam's axial strain
        (``fbg``) or the tip grating's load (``tip``)."""
        s = self.settings
        if s.contact == "event":
            return bool(f.flags & Status.CONTACT_EVENT)
        if s.contact == "tip":
            if tip_force is None or self.tip is None:
                return False
            return tip_force > max(s.tip_contact_sigmas * self.tip.noise(), s.tip_contact_floor)
        mode = s.fbg_bending_mode
        axial = axial_strain(eps, mode) if mode else -float(np.mean(eps))
        return axial > s.fbg_contact_strain

    def command(self, cmd: Command) -> None:
        if cmd.rezero and self.frames:
            # the machine held still for these ticks: the newest frames are all at rest
            self.chain = self._zero_on(self.frames[-REZERO_FRAMES:])
        if self._joints is None:
            return
        if not cmd.torque:
            self.release()
            return
        if self._stale:  # the servos did not answer this tick: hold the goal sent last
            return
        sp = self._setpoint or self._joints
        step = cmd.speed * self.settings.tick
        roll_step = self.settings.roll_speed * self.settings.tick
        target = JointState(
            roll=sp.roll + _clamp(cmd.roll - sp.roll, roll_step),
            translation=sp.translation + _clamp(cmd.advance - sp.translation, step),
        )
        try:
            # Keep the continuous setpoint: the goal sent is rounded to encoder ticks, and
            # feeding that back would stall motions slower than one tick per control period.
            self.drive.command(target)
            self._setpoint = target
        except (ServoFaultError, ServoTransportError):
            self._setpoint = sp  # observe() reports the fault on the next tick

    def recover(self) -> bool:
        """Reboot the servos that report a hardware error, then torque on again.

        Only faulted servos are rebooted: a Dynamixel reboot resets the multi-turn count, so
        the drive's homing offsets of a rebooted translation servo are only valid within one
        revolution; the state machine retracts slowly and the trial is marked FAULT anyway.
        """
        bus = self.drive.bus
        reboot = getattr(bus, "reboot", None)
        read_error = getattr(bus, "read_hardware_error", None)
        if reboot is None or read_error is None:
            return False
        try:
            for name in bus.names:
                if read_error(name):
                    reboot(name)
            bus.set_torque(True)
        except (ServoFaultError, ServoTransportError):
            return False
        self._setpoint = None
        return True

    def release(self) -> None:
        with contextlib.suppress(ServoFaultError, ServoTransportError, OSError):
            self.drive.bus.set_torque(False)

    # -- helpers -----------------------------------------------------------------------------
    def _receive(self) -> list[Frame]:
        """Frames that arrived since the last call. With ``sync_to_clock`` (simulation) wait, up
        to ``frame_wait_s`` of real time, until what the emulator sent up to the current clock
        time has come through the transport, so every path sees the same frames each tick."""
        frames = self.reader.poll()
        if self.settings.sync_to_clock:
            deadline = time.monotonic() + self.settings.frame_wait_s
            while self._behind() and self.reader.connected and time.monotonic() < deadline:
                frames += self.reader.read()
        self.frames += frames
        return frames

    def _behind(self) -> bool:
        """Simulation: has the emulator sent something the reader has not received yet?"""
        sent = self.settings.sent_bytes
        if sent is not None:
            return self.reader.counters.bytes_received < sent()
        # Without the emulator's count: the frame after the newest received is due if its time
        # (one frame period on) has come. The timestamps are whole microseconds, so the time is
        # known to half a microsecond; a frame the emulator holds back because its true time
        # is later than now (by more than its 0.1 us slack) is not waited for.
        last = self.reader.last_frame
        if last is None:
            return True
        return last.time + self.settings.frame_period <= self.clock.now() + 0.5e-6


def _clamp(x: float, limit: float) -> float:
    return max(-limit, min(limit, x))
