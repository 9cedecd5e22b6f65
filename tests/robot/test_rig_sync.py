"""The rig's wait for the emulator's frames in simulation: it waits for what was sent, never for a
frame that cannot have been sent (a control rate far above the board's rate used to wait 0.2 s of
wall time on almost every tick: 120 s for 0.058 s simulated). Counted on the virtual clock, no
timing asserted."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from palpate.config.schema import FbgConfig
from palpate.robot.drive import JointState
from palpate.robot.rig import RigSettings, ServoFbgRig
from palpate.sensor.reader import FrameReader
from palpate.sensor.strain import StrainChain
from palpate.sim.board import BoardEmulator, constant_source
from palpate.sim.clock import VirtualClock
from palpate.sim.inprocess import MemorySerial
from palpate.wire.frame import Frame, FrameLayout

LAYOUT = FrameLayout(3)
WAVELENGTHS = (1530e-9, 1535e-9, 1540e-9)
BOARD_HZ = 250.0
CONTROL_HZ = 10_000.0


class CountingReader(FrameReader):
    """A frame reader that counts its blocking reads (the rig's waits)."""

    blocking_reads = 0

    def read(self) -> list[Frame]:
        self.blocking_reads += 1
        return super().read()


class _NoTwist:
    def twist(self, shafts: object) -> float:
        return 0.0


class StillDrive:
    """The drive at rest: all ``observe`` needs (joints, motors, the gears' twist)."""

    drive = _NoTwist()

    def read(self) -> tuple[JointState, dict[str, object]]:
        return JointState(0.0, 0.0), {}


@pytest.fixture(params=["wire", "fast"])
def board(request: pytest.FixtureRequest) -> Iterator[tuple[BoardEmulator, VirtualClock, object]]:
    clock = VirtualClock()
    if request.param == "wire":
        emu = BoardEmulator(constant_source(WAVELENGTHS), LAYOUT, rate_hz=BOARD_HZ, clock=clock)
        port: object = emu.port
    else:
        port = MemorySerial()
        emu = BoardEmulator(
            constant_source(WAVELENGTHS), LAYOUT, rate_hz=BOARD_HZ, clock=clock, sink=port
        )
    with emu:
        yield emu, clock, port


@pytest.mark.parametrize("barrier", [True, False], ids=["sent-bytes", "frame-period"])
def test_a_control_rate_above_the_board_rate_never_waits_for_a_frame_not_sent(
    board: tuple[BoardEmulator, VirtualClock, object], barrier: bool
) -> None:
    emu, clock, port = board
    reader = CountingReader(port, LAYOUT, clock=clock, stale_timeout_s=0.1)  # type: ignore[arg-type]
    settings = RigSettings(
        tick=1.0 / CONTROL_HZ,
        sync_to_clock=True,
        sent_bytes=(lambda: emu.stats.bytes_sent) if barrier else None,
        frame_period=1.0 / BOARD_HZ,
        frame_wait_s=1000.0,  # a wait for a frame that cannot come would hang the test
    )
    rig = ServoFbgRig(StillDrive(), reader, StrainChain.from_config(FbgConfig()), clock, settings)  # type: ignore[arg-type]
    rig.zero(samples=2)
    ticks = int(0.1 * CONTROL_HZ)  # 0.1 s simulated: 1000 ticks, 25 frames
    waits_before = reader.blocking_reads
    period_ticks = round(CONTROL_HZ / BOARD_HZ)
    for i in range(ticks):
        clock.sleep(settings.tick)
        obs = rig.observe(clock.now())
        if i >= period_ticks:  # each frame is used on the tick it is due
            assert obs.stream_age <= 1.0 / BOARD_HZ + 1e-9
    # at most one wait per frame (a pty delivers a little after the write), none in between
    assert reader.blocking_reads - waits_before <= 0.1 * BOARD_HZ + 1
    assert reader.counters.frames == emu.stats.frames_sent
    reader.close()
