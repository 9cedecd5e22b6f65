"""The driver over the real dynamixel_sdk, against the emulator on a real pty (virtual time).

The emulator answers from a thread of this process, so on a busy machine a reply may take tens
of milliseconds of wall time: the reply timeout here is generous (1 s, which costs nothing when
the reply comes), and the tests where a reply must be missing run on the in-process port, where
a reply is there at once or never."""

from __future__ import annotations

import math
import os
from collections.abc import Iterator
from pathlib import Path

import dynamixel_sdk as sdk
import pytest

from palpate.config.schema import ServoBusConfig, ServoConfig
from palpate.robot.dynamixel.driver import DynamixelBus
from palpate.robot.dynamixel.roster import Motor
from palpate.robot.motors import ServoFaultError, ServoIdentityError, ServoTransportError
from palpate.sensor.ports import Backoff
from palpate.sim.clock import VirtualClock
from palpate.sim.dynamixel import protocol
from palpate.sim.dynamixel.bus import EmulatedBus
from palpate.sim.dynamixel.faults import FaultyBus
from palpate.sim.inprocess import InProcessPort
from palpate.wire import dynamixel as tables

CFG = ServoBusConfig(retries=2, timeout_ms=1000.0)
NAMES = ("outer_roll", "inner_roll", "translation")


@pytest.fixture
def clock() -> VirtualClock:
    return VirtualClock()


@pytest.fixture
def emulator(clock: VirtualClock) -> Iterator[EmulatedBus]:
    with EmulatedBus.from_config(CFG, clock=clock) as bus:
        yield bus


@pytest.fixture
def driver(emulator: EmulatedBus) -> Iterator[DynamixelBus]:
    with DynamixelBus.from_config(CFG, port=emulator.port) as bus:
        yield bus


@pytest.fixture
def silent(clock: VirtualClock) -> EmulatedBus:
    """An emulated bus for the in-process port (no pty): a dropped reply is known at once."""
    return EmulatedBus.from_config(CFG, clock=clock)


def in_process(bus: EmulatedBus, cfg: ServoBusConfig = CFG) -> DynamixelBus:
    port = InProcessPort(bus)
    port.reply_timeout_ms = 0.0
    return DynamixelBus.from_config(cfg, port=port)


def test_connect_identifies_and_sets_extended_position_mode(
    emulator: EmulatedBus, driver: DynamixelBus
) -> None:
    assert driver.names == NAMES
    assert driver.ping("translation") == 1060
    for s in emulator.servos:
        assert s.item("Operating_Mode") == tables.MODE_EXTENDED_POSITION
        assert not s.torque_enabled


def test_goals_reach_the_servos_signed_and_multi_turn(
    emulator: EmulatedBus, driver: DynamixelBus, clock: VirtualClock
) -> None:
    driver.max_goal_step = 100.0
    driver.set_torque(True)
    goals = {"outer_roll": -3.5 * 2 * math.pi, "inner_roll": 1.0, "translation": 9 * 2 * math.pi}
    sent = driver.write_goals(goals)
    assert sent == pytest.approx(goals, abs=2 * math.pi / 4096)
    state = driver.read_state()
    assert all(not s.moving for s in state.values())
    clock.advance(1.0)
    assert any(s.moving for s in driver.read_state().values())
    clock.advance(60.0)
    state = driver.read_state()
    for name, goal in goals.items():
        assert state[name].position == pytest.approx(goal, abs=2 * math.pi / 4096)
        assert state[name].velocity == 0.0
    assert emulator.servo(1).position_ticks == -3.5 * 4096


def test_goal_step_is_clamped_per_tick(driver: DynamixelBus) -> None:
    driver.set_torque(True)
    step = CFG.max_goal_step
    sent = driver.write_goals({"outer_roll": 5.0, "translation": -5.0})
    assert sent["outer_roll"] == pytest.approx(step, abs=1e-3)
    assert sent["translation"] == pytest.approx(-step, abs=1e-3)
    sent = driver.write_goals({"outer_roll": 5.0})
    assert sent["outer_roll"] == pytest.approx(2 * step, abs=1e-3)


def test_goals_the_servos_hold_already_are_not_sent(silent: EmulatedBus) -> None:
    """A tick whose goals round to the ticks last sent (a rest, a hold) sends no packet; the
    next new goal goes out as before."""
    with in_process(silent) as driver:
        driver.set_torque(True)
        first = driver.write_goals({"translation": 0.1})
        packets = silent.packets_handled
        assert driver.write_goals({"translation": 0.1 + 1e-4}) == first  # within one tick
        assert silent.packets_handled == packets
        driver.write_goals({"translation": 0.2})
        assert silent.packets_handled == packets + 1


def test_write_goals_needs_torque(driver: DynamixelBus) -> None:
    with pytest.raises(RuntimeError, match="torque"):
        driver.write_goals({"outer_roll": 0.1})


def test_profiles_are_written_in_servo_units(emulator: EmulatedBus, driver: DynamixelBus) -> None:
    driver.set_profile("translation", velocity=2 * math.pi, acceleration=4 * math.pi)
    servo = emulator.servo(3)
    assert servo.item("Profile_Velocity") == round(60 / 0.229)  # 1 rev/s
    assert servo.item("Profile_Acceleration") == round(2 * 3600 / 214.577)


def test_close_turns_torque_off_even_after_an_error(emulator: EmulatedBus) -> None:
    bus = DynamixelBus.from_config(CFG, port=emulator.port)

    def fail_with_torque_on() -> None:
        with bus:
            bus.set_torque(True)
            assert all(s.torque_enabled for s in emulator.servos)
            raise ZeroDivisionError

    with pytest.raises(ZeroDivisionError):
        fail_with_torque_on()
    assert not any(s.torque_enabled for s in emulator.servos)
    bus.close()  # idempotent


def test_close_releases_the_other_servos_when_one_is_silent(silent: EmulatedBus) -> None:
    bus = in_process(silent)
    bus.connect()
    bus.set_torque(True)
    silent.servo(1).drop_replies(100)
    bus.close()
    assert not silent.servo(2).torque_enabled
    assert not silent.servo(3).torque_enabled


def test_a_transient_lost_reply_is_retried(silent: EmulatedBus) -> None:
    with in_process(silent) as driver:
        silent.servo(2).drop_replies(1)
        silent.servo(3).corrupt_replies(1)
        before = driver.stats.copy()
        assert set(driver.read_state()) == set(NAMES)
        counted = driver.stats.since(before)
        assert counted.transactions == 1  # one read ...
        assert counted.retries == 1  # ... whose first attempt lost both replies (one sync read)
        assert counted.failures == 0


def test_a_silent_servo_ends_in_a_transport_error(silent: EmulatedBus) -> None:
    with in_process(silent) as driver:
        silent.servo(3).drop_replies(100)
        with pytest.raises(ServoTransportError, match="3 attempts") as info:
            driver.read_state()
        assert isinstance(info.value, OSError)
        silent.servo(3).corrupt_replies(100)
        silent.servo(3).drop_replies(0)
        with pytest.raises(ServoTransportError, match="Incorrect status packet"):
            driver.read_item("translation", "Present_Position")


def test_hardware_error_ends_in_a_fault_with_decoded_bits(
    emulator: EmulatedBus, driver: DynamixelBus
) -> None:
    driver.set_torque(True)
    emulator.servo(2).raise_hardware_error(tables.HW_OVERLOAD | tables.HW_OVERHEATING)
    with pytest.raises(ServoFaultError) as info:
        driver.read_state()
    fault = info.value
    assert isinstance(fault, RuntimeError)
    assert fault.servo_id == 2
    assert fault.hardware_error == 0x24
    assert fault.hardware_error_names == ("Overheating Error", "Overload Error")
    driver.reboot("inner_roll")
    assert driver.read_hardware_error("inner_roll") == 0
    assert set(driver.read_state()) == set(NAMES)


def test_a_stall_becomes_an_overload_fault(
    emulator: EmulatedBus, driver: DynamixelBus, clock: VirtualClock
) -> None:
    driver.set_torque(True)
    emulator.servo(3).set_stalled(True)
    driver.write_goals({"translation": 0.1})
    clock.advance(0.5)
    driver.read_state()
    clock.advance(1.0)
    with pytest.raises(ServoFaultError, match="Overload") as info:
        driver.read_state()
    assert info.value.servo_id == 3
    assert not emulator.servo(3).torque_enabled


def test_a_short_state_reply_is_a_transport_error(clock: VirtualClock) -> None:
    emulator = FaultyBus.from_config(CFG, clock=clock)
    with DynamixelBus.from_config(CFG, port=InProcessPort(emulator)) as driver:
        driver.set_torque(True)
        # well-formed status packets (valid CRC) with 2 of the 14 bytes asked for
        emulator.reply_filter = lambda _: b"".join(
            protocol.encode_status(i, 0, b"\x01\x02") for i in (1, 2, 3)
        )
        with pytest.raises(ServoTransportError, match="short reply"):
            driver.read_state()
        emulator.reply_filter = None


def test_access_error_is_a_fault_with_its_number(driver: DynamixelBus) -> None:
    driver.set_torque(True)
    with pytest.raises(ServoFaultError, match="Access Error") as info:
        driver.write_item("outer_roll", "Operating_Mode", 3)
    assert info.value.error_number == tables.ERR_ACCESS


def test_connect_refuses_a_servo_with_a_hardware_error(emulator: EmulatedBus) -> None:
    emulator.servo(1).raise_hardware_error(tables.HW_INPUT_VOLTAGE)
    with pytest.raises(ServoFaultError, match="Input Voltage"):
        DynamixelBus.from_config(CFG, port=emulator.port).connect()


def test_wrong_model_is_an_identity_error(emulator: EmulatedBus) -> None:
    # under load the emulator's thread may answer late: a generous reply timeout, not a race
    cfg = ServoBusConfig(
        translation=ServoConfig(id=3, model="XM430-W350"), retries=0, timeout_ms=1000.0
    )
    bus = DynamixelBus.from_config(cfg, port=emulator.port)
    with pytest.raises(ServoIdentityError, match="XL430-W250"):
        bus.connect()


def test_missing_servo_and_missing_port_are_transport_errors(silent: EmulatedBus) -> None:
    cfg = ServoBusConfig(translation=ServoConfig(id=9, model="XL430-W250"), retries=0)
    with pytest.raises(ServoTransportError, match="ping translation"):
        in_process(silent, cfg).connect()
    with pytest.raises(ServoTransportError, match="cannot open"):
        DynamixelBus.from_config(CFG, port="/nonexistent/ttyDXL").connect()


def test_an_adapter_unplugged_and_replugged_is_reopened(
    tmp_path: Path, emulator: EmulatedBus
) -> None:
    """The USB adapter's device goes away under the driver (the emulator's pty closes: EIO on
    the next write or read) and comes back at the same path: transport errors meanwhile, then
    the port is opened again and the servos, which kept their power, answer as before."""
    link = tmp_path / "ttyUSB0"
    link.symlink_to(emulator.port)
    with DynamixelBus.from_config(CFG, port=str(link)) as bus:
        bus.recovery.backoff = Backoff(0.0, 0.0)  # every attempt may reopen: no wall-time back-off
        bus.set_torque(True)
        emulator.close()  # unplugged: the device goes, and its name with it (udev), so that
        link.unlink()  # a pty another process opens meanwhile at the same number is not it
        for _ in range(2):  # lost, then reopening fails while the device is away
            with pytest.raises(ServoTransportError, match="lost"):
                bus.read_state()
        assert (bus.port_errors, bus.reopens) == (1, 0)
        link.symlink_to(emulator.open())  # plugged in again
        assert set(bus.read_state()) == set(NAMES)
        assert (bus.port_errors, bus.reopens) == (1, 1)
        assert all(s.torque_enabled for s in emulator.servos)
        bus.write_goals({"translation": 0.05})


def test_an_open_port_handler_can_be_passed_in(emulator: EmulatedBus) -> None:
    handler = sdk.PortHandler(emulator.port)
    with DynamixelBus(handler, [Motor("m", 2, "XM430-W350")]) as bus:
        assert bus.port_handler is handler
        assert bus.read_item("m", "Model_Number") == 1020


def test_constructor_rejects_bad_motor_lists() -> None:
    with pytest.raises(ValueError, match="unique"):
        DynamixelBus("/dev/null", [Motor("a", 1, "XM430-W350"), Motor("a", 2, "XM430-W350")])
    with pytest.raises(ValueError, match="unknown model"):
        DynamixelBus("/dev/null", [Motor("a", 1, "AX-12")])


@pytest.mark.hardware
def test_real_bus_reads_state() -> None:
    """On the bench: PALPATE_HW_SERVO_PORT=/dev/ttyUSB0 pytest -m hardware (torque stays off)."""
    port = os.environ.get("PALPATE_HW_SERVO_PORT")
    if not port:
        pytest.skip("no servo bus: set PALPATE_HW_SERVO_PORT")
    with DynamixelBus.from_config(ServoBusConfig(), port=port) as bus:
        assert set(bus.read_state()) == set(NAMES)


class _LateReads:
    """The SDK's packet handler whose next ``late`` register reads get no reply: a busy host
    (or an emulator starting beside it) answering past the timeout."""

    def __init__(self, late: int) -> None:
        self._inner = sdk.PacketHandler(2.0)
        self.late = late

    def readTxRx(self, port: object, servo_id: int, address: int, size: int) -> object:
        if self.late > 0:
            self.late -= 1
            return [], sdk.COMM_RX_TIMEOUT, 0
        return self._inner.readTxRx(port, servo_id, address, size)

    def __getattr__(self, name: str) -> object:
        return getattr(self._inner, name)


def test_connect_waits_its_patience_on_every_transaction_not_only_the_pings(
    silent: EmulatedBus,
) -> None:
    cfg = ServoBusConfig(retries=2, timeout_ms=20.0)  # 3 attempts a transaction; 0.5 s: 25
    port = InProcessPort(silent)
    port.reply_timeout_ms = 0.0
    late = _LateReads(late=6)  # the operating mode's read is late 6 times in a row
    with DynamixelBus.from_config(cfg, port=port, packet_handler=late) as driver:
        assert late.late == 0
        late.late = 6  # after connect the bus's own retries hold: 3 attempts
        with pytest.raises(ServoTransportError, match="3 attempts"):
            driver.read_item("translation", "Present_Position")
