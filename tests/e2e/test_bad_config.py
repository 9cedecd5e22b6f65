"""Bad configuration through the CLI: one clear message naming the file and the key, exit code
2, and nothing moved (no emulated servo bus is even created, no driver connects)."""

from __future__ import annotations

import errno
import os
from collections.abc import Iterator
from pathlib import Path

import dynamixel_sdk as sdk
import pytest
import serial

from palpate.cli import main
from palpate.config import resolve
from palpate.robot.dynamixel.driver import DynamixelBus
from palpate.robot.dynamixel.roster import Motor
from palpate.robot.motors import ServoTransportError
from palpate.sensor.ports import open_failure
from palpate.sensor.reader import FrameReader, SensorPortError
from palpate.sim.dynamixel.bus import EmulatedBus, Reply
from palpate.sim.dynamixel.protocol import Packet
from palpate.wire.frame import layout_of

ROBOT = resolve("robot.yaml").read_text(encoding="utf-8")
SCENE = resolve("scenes/robot.yaml").read_text(encoding="utf-8")


@pytest.fixture
def moves(monkeypatch: pytest.MonkeyPatch) -> Iterator[list[str]]:
    """Records every servo packet handled (as bytes, or decoded on the fast path) and every
    driver connect in this process."""
    seen: list[str] = []
    handle, exchange, connect = EmulatedBus.handle, EmulatedBus.exchange, DynamixelBus.connect

    def spy_handle(self: EmulatedBus, data: bytes) -> bytes:
        seen.append("packet")
        return handle(self, data)

    def spy_exchange(self: EmulatedBus, packet: Packet) -> list[Reply]:
        seen.append("packet")
        return exchange(self, packet)

    def spy_connect(self: DynamixelBus) -> None:
        seen.append("connect")
        connect(self)

    monkeypatch.setattr(EmulatedBus, "handle", spy_handle)
    monkeypatch.setattr(EmulatedBus, "exchange", spy_exchange)
    monkeypatch.setattr(DynamixelBus, "connect", spy_connect)
    return seen


def _scene(tmp_path: Path, text: str, robot_text: str | None = None) -> Path:
    if robot_text is not None:
        (tmp_path / "robot.yaml").write_text(robot_text, encoding="utf-8")
        text = text.replace("robot: robot.yaml", f"robot: {tmp_path / 'robot.yaml'}")
    path = tmp_path / "scene.yaml"
    path.write_text(text, encoding="utf-8")
    return path


# (what is wrong, scene text, robot text or None for the shipped one, file, key in the message)
CASES = [
    ("malformed YAML", SCENE.replace("campaign:\n", "campaign: [\n"), None, "scene", "line"),
    ("missing key", SCENE.replace("{name: S7, modulus_kpa: 1122.86,", "{name: S7,"), None,
     "scene", "samples[0].modulus_kpa: missing required key"),
    ("wrong type", SCENE.replace("control_rate_hz: 250", "control_rate_hz: fast"), None,
     "scene", "control_rate_hz: expected a number"),
    ("unit left out of a key", SCENE.replace("exposed_length_mm: 42", "exposed_length: 0.042"),
     None, "scene", "campaign.exposed_length: unknown key"),
    ("Pa given where kPa is asked", SCENE.replace("modulus_kpa: 314.53", "modulus_kpa: 314530000"),
     None, "scene", "samples[1].modulus_kpa: must be <= 1000000.0"),
    ("unknown tube", SCENE.replace("tubes: [straight,", "tubes: [curly,"), None, "scene",
     "campaign.tubes[0]: no tube named 'curly'"),
    ("limits reversed", SCENE,
     ROBOT.replace("translation_min_mm: 0\n", "translation_min_mm: 90\n"), "robot",
     "drive: translation_min_mm must be below translation_max_mm"),
    ("tube that cannot reach", SCENE,
     ROBOT.replace("translation_max_mm: 80", "translation_max_mm: 30"), "scene",
     "campaign: trial S7-straight-downward-L42: target not reachable"),
    # a tip grating (issue 28) that cannot work
    ("tip grating of sensitivity 0", SCENE,
     ROBOT.replace("sensor:\n", "sensor:\n  tip_grating: {sensitivity_pm_per_mn: 0}\n"),
     "robot", "sensor.tip_grating.sensitivity_pm_per_mn: must be > 0"),
    ("tip grating compensated without a reference grating", SCENE,
     ROBOT.replace("sensor:\n", "sensor:\n  tip_grating: {temperature_compensation: reference}\n"),
     "robot", "sensor.tip_grating.temperature_compensation: 'reference' needs a strain-free"),
    ("contact from a tip grating the sensor lacks",
     SCENE.replace("contact: event ", "contact: tip   "), None, "scene",
     "campaign.contact: 'tip' needs a tip force grating"),
    ("buckling from a tip grating the sensor lacks",
     SCENE.replace("detector: paper ", "detector: tip   "), None, "scene",
     "campaign.detector: 'tip' needs a tip force grating"),
    ("an exposed length that leaves a grating in the tube",
     SCENE.replace("exposed_length_mm: 42", "exposed_length_mm: 25"), None, "scene",
     "campaign.exposed_length_mm: 25 mm leaves a grating inside the tube"),
]  # fmt: skip


@pytest.mark.parametrize(
    ("what", "scene", "robot", "file", "key"), CASES, ids=[c[0] for c in CASES]
)
def test_bad_configuration_exits_2_naming_file_and_key_and_nothing_moves(
    what: str,
    scene: str,
    robot: str | None,
    file: str,
    key: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    moves: list[str],
) -> None:
    assert scene != SCENE or robot not in (None, ROBOT)  # the case really breaks something
    path = _scene(tmp_path, scene, robot)
    code = main(["sim", "--scene", str(path), "--workers", "1", "--no-plots",
                 "--out", str(tmp_path / "out")])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.count("\n") == 1, err  # one message, no traceback
    expected_file = path if file == "scene" else tmp_path / "robot.yaml"
    assert str(expected_file) in err
    assert key in err
    assert moves == []  # nothing moved: no servo packet, no driver connect


@pytest.mark.slow
def test_the_spy_sees_a_good_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], moves: list[str]
) -> None:
    """The nothing-moved check above could fail: a good scene does reach the servos."""
    path = _scene(tmp_path, SCENE)
    code = main(["sim", "--scene", str(path), "--workers", "1", "--no-plots", "--limit", "1",
                 "--out", str(tmp_path / "out")])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    assert "connect" in moves
    assert "packet" in moves


# -- serial permission errors: which port, and what to do ------------------------------------


class _DeniedPort(sdk.PortHandler):  # type: ignore[misc]  # the SDK is untyped
    """A servo port whose open fails as pyserial does without access to the device."""

    def openPort(self) -> bool:
        raise serial.SerialException(
            errno.EACCES, f"could not open port {self.port_name}: [Errno 13] Permission denied"
        )


def test_servo_port_permission_error_names_port_and_dialout() -> None:
    bus = DynamixelBus(_DeniedPort("/dev/ttyUSB7"), [Motor("a", 1, "XM430-W350")])
    with pytest.raises(ServoTransportError) as info:
        bus.connect()
    text = str(info.value)
    assert "/dev/ttyUSB7" in text
    assert "dialout" in text
    assert "udev" in text


@pytest.mark.skipif(os.geteuid() == 0, reason="root ignores file permissions")
def test_board_port_permission_error_on_an_unreadable_device(tmp_path: Path) -> None:
    master, slave = os.openpty()
    try:
        name = os.ttyname(slave)
        os.chmod(name, 0)
        with pytest.raises(SensorPortError) as info:
            FrameReader(name, layout_of(3))
        assert name in str(info.value)
        assert "dialout" in str(info.value)
    finally:
        os.close(master)
        os.close(slave)


def test_board_port_permission_error_message() -> None:
    denied = serial.SerialException(errno.EACCES, "could not open port /dev/ttyACM0: denied")
    text = open_failure("board", "/dev/ttyACM0", denied)
    assert "'/dev/ttyACM0'" in text
    assert "dialout" in text
    other = open_failure("board", "/dev/ttyACM0", serial.SerialException(errno.ENOENT, "gone"))
    assert "dialout" not in other


def test_board_port_that_does_not_exist_names_the_port(tmp_path: Path) -> None:
    missing = str(tmp_path / "ttyNOPE")
    with pytest.raises(SensorPortError, match="ttyNOPE"):
        FrameReader(missing, layout_of(3))
