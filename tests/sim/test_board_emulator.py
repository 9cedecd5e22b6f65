"""The board emulator on a real pty, read by the sensor reader: exact counts under every fault."""

from __future__ import annotations

import numpy as np
import pytest

from palpate.sensor.reader import FrameReader
from palpate.sim.board import BoardEmulator, BoardFaults, BoardSample, constant_source
from palpate.sim.clock import VirtualClock
from palpate.sim.inprocess import FramePipe, MemorySerial
from palpate.wire.frame import FrameLayout, Status

LAYOUT = FrameLayout(3)
WAVELENGTHS = (1530e-9, 1535e-9, 1540e-9)
STEP = 0.01  # virtual seconds per control tick


def run(emu: BoardEmulator, reader: FrameReader, clock: VirtualClock, seconds: float) -> int:
    frames = 0
    for _ in range(round(seconds / STEP)):
        clock.advance(STEP)
        frames += len(reader.read_bytes(emu.stats.bytes_sent, timeout_s=10.0))
        reader.check_stale()
    return frames


def read_until_lost(reader: FrameReader) -> None:
    """Read until the port fails (the writer thread closes the pty asynchronously; a generous
    bound, ended by the condition)."""
    for _ in range(1000):
        reader.read()
        if not reader.connected:
            return
    pytest.fail("the port never failed")


def test_clean_stream_on_a_virtual_clock() -> None:
    clock = VirtualClock()

    def source(t: float) -> BoardSample:
        return BoardSample(wavelengths=WAVELENGTHS, encoder=round(t * 1000), force=0.5)

    layout = FrameLayout(3, has_force=True)
    with (
        BoardEmulator(source, layout, rate_hz=1000, clock=clock) as emu,
        FrameReader(emu.port, layout, clock=clock) as reader,
    ):
        clock.advance(0.0095)
        frames = reader.read_frames(9, timeout_s=10.0)
        assert [f.seq for f in frames] == list(range(9))
        assert [f.timestamp_us for f in frames] == [1000 * (k + 1) for k in range(9)]
        assert [f.encoder for f in frames] == [k + 1 for k in range(9)]
        assert frames[0].force == pytest.approx(0.5)
        assert frames[0].wavelengths.tolist() == pytest.approx(list(WAVELENGTHS), rel=1e-12)
        assert run(emu, reader, clock, 0.5) == 500
        assert reader.counters.frames == emu.stats.frames_sent == 509
        assert reader.counters.bytes_discarded == 0


@pytest.mark.parametrize("seed", [0, 1])
def test_every_fault_mode_gives_exact_counts(seed: int) -> None:
    clock = VirtualClock()
    faults = BoardFaults(
        garbage_probability=0.05,
        bitflip_probability=0.04,
        truncate_probability=0.02,
        drop_probability=0.03,
        stall_probability=0.002,
        stall_s=0.3,
        seed=seed,
    )
    source = constant_source(WAVELENGTHS)
    with (
        BoardEmulator(source, LAYOUT, clock=clock, faults=faults, record=True) as emu,
        FrameReader(emu.port, LAYOUT, clock=clock, stale_timeout_s=0.1) as reader,
    ):
        got = run(emu, reader, clock, 4.0)
        while True:  # run on until a valid frame arrived after the last stall began
            stalls = [d for _, outcome, d in emu.stats.log if outcome == "stall"]
            last = reader.last_frame
            if last is not None and (not stalls or last.timestamp_us > stalls[-1]):
                break
            got += run(emu, reader, clock, STEP)
    s, c = emu.stats, reader.counters
    corrupt = [d for _, outcome, d in s.log if outcome in ("bitflip", "truncate")]
    lost = sorted(seq for seq, outcome, _ in s.log if outcome not in ("sent", "stall"))
    sent = [seq for seq, outcome, _ in s.log if outcome == "sent"]
    lost_inside = [q for q in lost if sent[0] < q < sent[-1]]
    runs = sum(1 for i, q in enumerate(lost_inside) if i == 0 or lost_inside[i - 1] != q - 1)
    assert s.stalls > 0
    assert s.garbage_bursts > 0
    assert s.frames_dropped > 0
    assert c.bytes_received == s.bytes_sent
    assert got == c.frames == s.frames_sent
    assert c.frames_lost == len(lost_inside)
    assert c.seq_gaps == runs
    assert c.crc_errors == sum(d >= 6 for d in corrupt)
    assert c.bad_headers == sum(3 <= d < 6 for d in corrupt)
    assert c.stale_events == s.stalls
    assert c.out_of_order == 0


def test_disconnect_is_a_lost_port_counted_by_the_reader() -> None:
    clock = VirtualClock()
    emu = BoardEmulator(constant_source(WAVELENGTHS), LAYOUT, clock=clock)
    with emu, FrameReader(emu.port, LAYOUT, clock=clock) as reader:
        clock.advance(0.05)
        assert len(reader.read_frames(50, timeout_s=10.0)) == 50
        emu.disconnect()
        read_until_lost(reader)
        assert reader.counters.port_errors == 1
        clock.advance(1.0)
        assert reader.poll() == []  # reopening fails: the pty is gone
        assert reader.stale
        assert reader.counters.reopens == 0


def test_disconnect_after_a_configured_time() -> None:
    clock = VirtualClock()
    faults = BoardFaults(disconnect_after_s=0.02)
    emu = BoardEmulator(constant_source(WAVELENGTHS), LAYOUT, clock=clock, faults=faults)
    with emu, FrameReader(emu.port, LAYOUT, clock=clock) as reader:
        clock.advance(0.05)
        assert emu.stats.disconnected
        assert emu.stats.samples == 19
        read_until_lost(reader)
        assert reader.counters.port_errors == 1


def test_free_running_streams_in_real_time() -> None:
    with (
        BoardEmulator(constant_source(WAVELENGTHS), LAYOUT, rate_hz=2000) as emu,
        FrameReader(emu.port, LAYOUT, read_timeout_s=0.5) as reader,
    ):
        frames = reader.read_frames(20, timeout_s=10.0)
    assert len(frames) >= 20
    seqs = [f.seq for f in frames]
    assert seqs == sorted(seqs)


def test_source_with_the_wrong_layout_is_refused() -> None:
    clock = VirtualClock()
    source = constant_source(WAVELENGTHS[:2])
    with BoardEmulator(source, LAYOUT, clock=clock), pytest.raises(ValueError, match="streams"):
        clock.advance(0.01)


def test_overrun_flag_when_the_transmit_buffer_is_full() -> None:
    clock = VirtualClock()
    emu = BoardEmulator(constant_source(WAVELENGTHS), LAYOUT, clock=clock, queue_chunks=1)
    with emu, FrameReader(emu.port, LAYOUT, clock=clock) as reader:
        for _ in range(200):  # nobody reads: the pty fills, then the queue
            clock.advance(0.05)
        assert emu.stats.overruns > 0
        assert emu.stats.frames_sent + emu.stats.frames_dropped == emu.stats.samples
        frames = reader.read_bytes(emu.stats.bytes_sent, timeout_s=10.0)
        clock.advance(0.01)
        frames += reader.read_bytes(emu.stats.bytes_sent, timeout_s=10.0)
    assert any(f.status & Status.OVERRUN for f in frames)


def test_faults_validate() -> None:
    with pytest.raises(ValueError, match="bitflip"):
        BoardFaults(bitflip_probability=0.7, truncate_probability=0.7).validate()


def test_without_faults_the_fault_generator_is_never_drawn() -> None:
    """With every fault off the board sends each frame without drawing: the draws would decide
    nothing, and a fault-free stream costs no random numbers."""
    clock = VirtualClock()
    sink = _Sink()
    emu = BoardEmulator(constant_source(WAVELENGTHS), LAYOUT, clock=clock, sink=sink)
    before = emu._injector.rng.bit_generator.state
    with emu:
        clock.advance(0.1)
    assert emu._injector.rng.bit_generator.state == before
    assert emu.stats.frames_sent == emu.stats.samples == 100
    assert len(sink.data) == 100 * LAYOUT.size
    assert not BoardFaults().random
    assert BoardFaults(drop_probability=0.01).random


def test_wavelengths_may_be_any_sequence() -> None:
    sent = []
    for wavelengths in (list(WAVELENGTHS), WAVELENGTHS, np.asarray(WAVELENGTHS)):
        sample = BoardSample(wavelengths=wavelengths)

        def source(t: float, sample: BoardSample = sample) -> BoardSample:
            return sample

        clock, sink = VirtualClock(), _Sink()
        with BoardEmulator(source, LAYOUT, clock=clock, sink=sink):
            clock.advance(0.01)
        sent.append(sink.data)
    assert sent[0] == sent[1] == sent[2] != b""


class _Sink:
    name = "memory://test"

    def __init__(self) -> None:
        self.data = b""

    def write(self, data: bytes) -> int:
        self.data += data
        return len(data)


def _stream(in_memory: str) -> tuple[list[object], dict[str, int]]:
    """Two seconds of a moving source through bytes in memory or through a frame pipe."""
    clock = VirtualClock()

    def source(t: float) -> BoardSample:
        w = tuple(x * (1.0 + 1e-4 * np.sin(40 * t + k)) for k, x in enumerate(WAVELENGTHS))
        return BoardSample(wavelengths=w, encoder=round(t * 1e4) - 7, force=-0.25 + t, flags=1)

    layout = FrameLayout(3, has_reference=True, has_force=True)

    def src(t: float) -> BoardSample:
        return source(t)._replace(reference=1550e-9)

    if in_memory == "frames":
        pipe: FramePipe | MemorySerial = FramePipe()
        emu = BoardEmulator(src, layout, rate_hz=500, clock=clock, frame_sink=pipe)
    else:
        pipe = MemorySerial()
        emu = BoardEmulator(src, layout, rate_hz=500, clock=clock, sink=pipe)
    frames: list[object] = []
    with emu, FrameReader(pipe, layout, clock=clock) as reader:
        for _ in range(500):
            clock.advance(0.004)
            frames += reader.poll()
    return frames, reader.counters.as_dict()


def test_a_frame_sink_delivers_what_the_bytes_deliver() -> None:
    by_bytes, counted_bytes = _stream("bytes")
    by_frames, counted_frames = _stream("frames")
    assert len(by_bytes) == 1000
    assert by_frames == by_bytes
    assert counted_frames == counted_bytes


def test_a_frame_sink_refuses_byte_faults() -> None:
    with pytest.raises(ValueError, match="frame sink"):
        BoardEmulator(
            constant_source(WAVELENGTHS),
            LAYOUT,
            clock=VirtualClock(),
            frame_sink=FramePipe(),
            faults=BoardFaults(drop_probability=0.1),
        )
