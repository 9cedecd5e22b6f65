"""The reader over pyserial: loop:// round trips, stale detection, a missing port, a port lost
under the reader and reopened."""

from __future__ import annotations

import os
import pty
import tty
from pathlib import Path

import pytest
import serial

from palpate.config.schema import BoardConfig, SensorConfig
from palpate.sensor.parser import layout_from_config
from palpate.sensor.reader import REOPEN_BACKOFF_S, FrameReader, SensorPortError
from palpate.sim.clock import VirtualClock
from palpate.wire.frame import Frame, FrameLayout, encode

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


def test_a_closed_port_is_a_transient_reopened_with_back_off(loop: serial.SerialBase) -> None:
    clock = VirtualClock()
    reader = FrameReader(loop, LAYOUT, clock=clock, stale_timeout_s=0.1)
    loop.close()
    assert reader.poll() == []  # counted, not raised
    assert (reader.counters.port_errors, reader.connected) == (1, False)
    assert reader.poll() == []  # within the back-off: no new attempt
    assert reader.counters.reopens == 0
    clock.advance(REOPEN_BACKOFF_S[0])
    assert reader.poll() == []  # reopened (pyserial objects open their port again)
    assert (reader.counters.reopens, reader.connected) == (1, True)
    loop.write(encode(make(1)))
    assert [f.seq for f in reader.read_frames(1, timeout_s=5.0)] == [1]


class Unplugged:
    """A transport whose every read fails the way pyserial reports an unplugged device."""

    port = "/dev/ttyUSB-gone"
    in_waiting = 1

    def read(self, size: int = 1) -> bytes:
        raise serial.SerialException(
            "device reports readiness to read but returned no data "
            "(device disconnected or multiple access on port?)"
        )

    def close(self) -> None:
        pass


def test_readiness_without_data_is_counted_and_the_stream_goes_stale() -> None:
    clock = VirtualClock()
    reader = FrameReader(Unplugged(), LAYOUT, clock=clock, stale_timeout_s=0.1)
    for _ in range(50):  # 0.5 s of 10 ms polls: the back-off doubles, never raises
        assert reader.poll() == []
        clock.advance(0.01)
    assert reader.stale
    assert 2 <= reader.counters.port_errors < 10  # attempts spaced by the back-off
    assert "readiness to read" in reader.last_port_error


def _plug(link: Path) -> tuple[int, int]:
    """A new pty (the board plugged in) whose slave ``link`` points to."""
    master, slave = pty.openpty()
    tty.setraw(slave)
    link.unlink(missing_ok=True)
    link.symlink_to(os.ttyname(slave))
    return master, slave


def _send(master: int, seqs: range) -> None:
    os.write(master, b"".join(encode(make(i)) for i in seqs))


def test_a_pty_closed_under_the_reader_then_replugged(tmp_path: Path) -> None:
    """The board unplugged (its pty's master closed: the slave hangs up and unread bytes are
    gone) and plugged in again at the same path: counted, reopened, frames flow again."""
    clock = VirtualClock()
    link = tmp_path / "ttyBOARD"
    master, slave = _plug(link)
    reader = FrameReader(str(link), LAYOUT, clock=clock, stale_timeout_s=0.1)
    _send(master, range(3))
    assert [f.seq for f in reader.read_frames(3, timeout_s=5.0)] == [0, 1, 2]
    _send(master, range(3, 6))  # sent, never read: lost with the hang-up
    os.close(master)
    os.close(slave)
    link.unlink()  # the device's name goes with it: a pty opened meanwhile at its number is not it
    for _ in range(20):  # EIO / EOF, then failed reopenings while unplugged: never raises
        assert reader.poll() == []
        clock.advance(0.01)
    assert reader.counters.port_errors == 1
    assert not reader.connected
    assert reader.stale  # the trial's FBG-lost guard sees this
    master, slave = _plug(link)
    clock.advance(REOPEN_BACKOFF_S[1])
    assert reader.poll() == []
    assert (reader.connected, reader.counters.reopens) == (True, 1)
    _send(master, range(6, 8))
    assert [f.seq for f in reader.read_frames(2, timeout_s=5.0)] == [6, 7]
    assert not reader.stale
    assert reader.counters.frames_lost == 3
    reader.close()
    os.close(master)
    os.close(slave)


def test_layout_from_config() -> None:
    layout = layout_from_config(SensorConfig(), BoardConfig(has_force=True))
    assert layout == FrameLayout(3, has_reference=False, has_force=True)


def test_bad_stale_timeout() -> None:
    with pytest.raises(ValueError, match="stale_timeout_s"):
        FrameReader("loop://", LAYOUT, stale_timeout_s=0)
