"""A servo read missed on a busy host is not a fault: the rig holds the motion, marks the tick's
joints stale (the record keeps no advance for it) and reports the bus lost only when it has
stayed silent for ``bus_silence``. On the virtual clock; the drive is a stand-in whose reads
fail on demand (the driver's own retries: ``test_dynamixel_driver.py``)."""

from __future__ import annotations

import math

from palpate.config.schema import FbgConfig
from palpate.robot.drive import JointState
from palpate.robot.indentation import Command
from palpate.robot.motors import ServoTransportError
from palpate.robot.rig import RigSettings, ServoFbgRig
from palpate.sensor.reader import FrameReader
from palpate.sensor.strain import StrainChain
from palpate.sim.board import BoardEmulator, constant_source
from palpate.sim.clock import VirtualClock
from palpate.sim.inprocess import MemorySerial
from palpate.wire.frame import FrameLayout

LAYOUT = FrameLayout(3)
TICK = 0.004


class _NoTwist:
    def twist(self, shafts: object) -> float:
        return 0.0


class FlakyDrive:
    """A drive at 10 mm whose next ``silent`` reads fail as a transport error; it records the
    goals it is sent."""

    drive = _NoTwist()

    def __init__(self) -> None:
        self.silent = 0
        self.sent: list[JointState] = []

    def read(self) -> tuple[JointState, dict[str, object]]:
        if self.silent > 0:
            self.silent -= 1
            raise ServoTransportError("sync read of present state: no status packet (4 attempts)")
        return JointState(0.0, 10e-3), {}

    def command(self, q: JointState) -> JointState:
        self.sent.append(q)
        return q


def rig_and_clock() -> tuple[ServoFbgRig, FlakyDrive, VirtualClock, BoardEmulator]:
    clock = VirtualClock()
    port = MemorySerial()
    emu = BoardEmulator(
        constant_source((1530e-9, 1535e-9, 1540e-9)), LAYOUT, rate_hz=1000, clock=clock, sink=port
    )
    reader = FrameReader(port, LAYOUT, clock=clock, stale_timeout_s=0.1)  # type: ignore[arg-type]
    drive = FlakyDrive()
    settings = RigSettings(tick=TICK, bus_silence=0.05)
    rig = ServoFbgRig(drive, reader, StrainChain.from_config(FbgConfig()), clock, settings)  # type: ignore[arg-type]
    emu.start()
    rig.zero(samples=2)
    return rig, drive, clock, emu


def test_missed_reads_hold_the_motion_and_mark_the_ticks_until_the_bus_answers() -> None:
    rig, drive, clock, emu = rig_and_clock()
    with emu:
        go = Command(advance=20e-3, roll=0.0, speed=1e-3)
        assert rig.observe(clock.now()).joints_age == 0.0
        rig.command(go)
        assert len(drive.sent) == 1
        drive.silent = 5  # 20 ms of missed replies, under bus_silence
        for k in range(5):
            clock.sleep(TICK)
            obs = rig.observe(clock.now())
            assert obs.servo_fault is None
            assert not obs.bus_lost
            assert math.isclose(obs.joints_age, (k + 1) * TICK)
            assert obs.advance == 10e-3  # the last joints read ...
            assert math.isnan(obs.measured_advance)  # ... which the record does not keep
            rig.command(go)
        assert len(drive.sent) == 1  # no goal while the servos were silent: the motion held
        clock.sleep(TICK)
        obs = rig.observe(clock.now())
        assert obs.joints_age == 0.0
        assert obs.measured_advance == 10e-3
        rig.command(go)
        assert len(drive.sent) == 2  # streaming again
        assert rig.missed_reads == 5


def test_a_bus_silent_for_longer_than_its_bound_is_lost() -> None:
    rig, drive, clock, emu = rig_and_clock()
    with emu:
        rig.observe(clock.now())
        drive.silent = 100
        faults = []
        for _ in range(20):  # 80 ms against a 50 ms bound
            clock.sleep(TICK)
            obs = rig.observe(clock.now())
            faults.append(obs.bus_lost)
        first = faults.index(True)
        assert all(faults[first:])
        assert (first + 1) * TICK >= 0.05 - 1e-9  # not before the bound
        assert first * TICK < 0.05  # and at the first tick past it
        assert obs.servo_fault is not None
        assert "silent" in obs.servo_fault


def test_a_first_read_missed_is_held_and_a_bus_silent_from_the_start_is_lost() -> None:
    """The trial's first read missed (the rehearsal beside a campaign: it faulted at once):
    held, no goal sent, no joints; silent from the first tick for the bound: lost."""
    rig, drive, clock, emu = rig_and_clock()
    with emu:
        drive.silent = 1
        obs = rig.observe(clock.now())
        assert not obs.bus_lost
        assert math.isnan(obs.advance)
        rig.command(Command(advance=20e-3, roll=0.0, speed=1e-3))
        assert drive.sent == []
        clock.sleep(TICK)
        assert rig.observe(clock.now()).measured_advance == 10e-3  # it answers: streaming
        rig2, drive2, clock2, emu2 = rig_and_clock()
        with emu2:
            drive2.silent = 100
            lost = []
            for _ in range(20):
                lost.append(rig2.observe(clock2.now()).bus_lost)
                clock2.sleep(TICK)
            assert lost.index(True) == math.ceil(0.05 / TICK)  # silent 50 ms from the first tick


def test_a_host_that_did_not_run_the_rig_is_not_a_lost_bus() -> None:
    """Beside a heavy load the rig's process may not run for longer than the bound: two reads
    missed across a 300 ms gap (the rehearsal in CI: "silent 268 ms" after 2 missed reads) are
    held; the bus is lost only when it also missed ``bus_missed_reads`` reads in a row."""
    rig, drive, clock, emu = rig_and_clock()
    with emu:
        rig.observe(clock.now())
        drive.silent = 2
        clock.sleep(TICK)
        assert not rig.observe(clock.now()).bus_lost
        clock.sleep(0.3)  # the host was away, six bounds long
        assert not rig.observe(clock.now()).bus_lost  # the second missed read only
        clock.sleep(TICK)
        obs = rig.observe(clock.now())
        assert obs.joints_age == 0.0  # the bus answered: it was never lost
        drive.silent = 3
        lost = []
        for _ in range(3):
            clock.sleep(0.03)
            lost.append(rig.observe(clock.now()).bus_lost)
        assert lost == [False, False, True]  # 90 ms and the third read missed in a row
