"""The driver warns on connect when the USB adapter's latency timer (Linux sysfs) is above 1 ms,
saying how to fix it; a fake sysfs folder stands in for /sys/bus/usb-serial/devices."""

from __future__ import annotations

import logging
import os
from collections.abc import Iterator
from pathlib import Path

import pytest

from palpate.config.schema import ServoBusConfig
from palpate.robot.dynamixel.driver import DynamixelBus
from palpate.robot.dynamixel.latency import latency_timer_ms, latency_timer_path, latency_warning
from palpate.robot.dynamixel.roster import Motor
from palpate.sim.clock import VirtualClock
from palpate.sim.dynamixel.bus import EmulatedBus

CFG = ServoBusConfig(retries=1, timeout_ms=200.0)
NAMES = ("outer_roll", "inner_roll", "translation")


@pytest.fixture
def emulator() -> Iterator[EmulatedBus]:
    with EmulatedBus.from_config(CFG, clock=VirtualClock()) as bus:
        yield bus


def _fake_sysfs(root: Path, port: str, value: str) -> Path:
    folder = root / os.path.basename(os.path.realpath(port))
    folder.mkdir(parents=True)
    (folder / "latency_timer").write_text(value, encoding="ascii")
    return root


def test_connect_warns_about_a_16_ms_timer_and_says_how_to_fix_it(
    emulator: EmulatedBus, tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    sysfs = _fake_sysfs(tmp_path / "sys", emulator.port, "16\n")
    with (
        caplog.at_level(logging.WARNING),
        DynamixelBus.from_config(CFG, port=emulator.port) as _,
    ):
        pass  # the default sysfs: a pty has no latency timer, nothing to say
    assert not caplog.records
    motors = [Motor(n, getattr(CFG, n).id, getattr(CFG, n).model) for n in NAMES]
    driver = DynamixelBus(emulator.port, motors, usb_serial_sysfs=sysfs)
    with caplog.at_level(logging.WARNING), driver:
        pass
    [record] = caplog.records
    text = record.getMessage()
    assert record.levelno == logging.WARNING
    assert "latency timer is 16 ms" in text
    assert f"echo 1 | sudo tee {latency_timer_path(emulator.port, sysfs)}" in text
    assert 'ATTR{latency_timer}="1"' in text


def test_a_1_ms_timer_or_none_at_all_is_quiet(emulator: EmulatedBus, tmp_path: Path) -> None:
    sysfs = _fake_sysfs(tmp_path / "sys", emulator.port, "1\n")
    assert latency_timer_ms(emulator.port, sysfs) == 1
    assert latency_warning(emulator.port, sysfs) is None
    assert latency_warning(emulator.port, tmp_path / "elsewhere") is None
    (latency_timer_path(emulator.port, sysfs)).write_text("garbage", encoding="ascii")
    assert latency_timer_ms(emulator.port, sysfs) is None


def test_the_timer_is_found_through_a_symlinked_port(tmp_path: Path, emulator: EmulatedBus) -> None:
    link = tmp_path / "ttyU2D2"
    link.symlink_to(emulator.port)  # as a udev rule's /dev/serial/by-id/... name would be
    sysfs = _fake_sysfs(tmp_path / "sys", emulator.port, "4")
    assert latency_timer_ms(str(link), sysfs) == 4
    assert latency_timer_ms(os.path.basename(emulator.port), sysfs) == 4
    message = latency_warning(str(link), sysfs)
    assert message is not None
    assert "about 250 Hz at most" in message
