"""The reader over pyserial: loop:// round trips, stale detection, a missing port."""

from __future__ import annotations

import pytest
import serial

from config.schema import BoardConfig, SensorConfig
from sensor.reader import FrameReader, SensorPortError, layout_from_config
from sim.clock import VirtualClock
from wire.frame import Frame, FrameLayout, encode

LAYOUT = FrameLayout(3)


def make(seq: int) -> Frame:
    return Frame(seq, 1000 * seq, 0, 0, (1_530_000_000, 1_535_000_000, 1_540_000_000))


@pytest.fixture
def loop() -> serial.SerialBase:
    return serial.serial_for_url("loop://", timeout=0.5)


def test_reader_over_loop_url_string() -> None:
    with FrameReader("loop://", LAYOUT, read_timeout_s=0.5) as reader:
        transport = reader._serial
        assert isinstance(transport, serial.SerialBase)
        transport.write(b"\x00garbage" + b"".join(encode(make(i)) for i in range(5)))
        frames = reader.read_frames(5, timeout_s=5.0)
    assert [f.seq for f in frames] == list(range(5))
    assert reader.counters.bytes_discarded == 8


def test_reader_over_an_open_serial_object(loop: serial.SerialBase) -> None:
    clock = VirtualClock()
    reader = FrameReader(loop, LAYOUT, clock=clock, stale_timeout_s=0.1)
    loop.write(encode(make(0)) + encode(make(2)))
    frames = reader.read_frames(2, timeout_s=5.0)
    assert [f.seq for f in frames] == [0, 2]
    assert (reader.counters.seq_gaps, reader.counters.frames_lost) == (1, 1)
    assert reader.last_frame == frames[-1]
    reader.close()


def test_stale_on_the_injected_clock(loop: serial.SerialBase) -> None:
    clock = VirtualClock()
    reader = FrameReader(loop, LAYOUT, clock=clock, stale_timeout_s=0.1)
    assert not reader.stale
    clock.advance(0.05)
    assert reader.poll() == []
    assert not reader.stale
    clock.advance(0.06)
    assert reader.stale
    assert reader.stale  # one event per fresh -> stale change
    assert reader.counters.stale_events == 1
    loop.write(encode(make(0)))
    assert len(reader.read_frames(1, timeout_s=5.0)) == 1
    assert not reader.stale
    clock.advance(0.2)
    assert reader.poll() == []
    assert reader.counters.stale_events == 2
    reader.close()


def test_missing_port_names_the_port() -> None:
    with pytest.raises(SensorPortError, match="/dev/does-not-exist-fbg") as info:
        FrameReader("/dev/does-not-exist-fbg", LAYOUT)
    assert isinstance(info.value, OSError)


def test_read_on_a_closed_port_is_a_port_error(loop: serial.SerialBase) -> None:
    reader = FrameReader(loop, LAYOUT)
    loop.close()
    with pytest.raises(SensorPortError, match="loop"):
        reader.poll()


def test_layout_from_config() -> None:
    layout = layout_from_config(SensorConfig(), BoardConfig(has_force=True))
    assert layout == FrameLayout(3, has_reference=False, has_force=True)


def test_bad_stale_timeout() -> None:
    with pytest.raises(ValueError, match="stale_timeout_s"):
        FrameReader("loop://", LAYOUT, stale_timeout_s=0)
