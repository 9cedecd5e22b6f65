"""Open the bench's real interfaces: the servo bus and the acquisition board, on the ports named.

:func:`open_hardware` is a context manager that opens the board's stream first, then the
Dynamixel bus through the real ``dynamixel_sdk`` (connect, identify, profiles, software homing,
torque on), and on the way out always turns torque off and closes both ports, whatever happened.
Ports are parameters: device paths on the bench, the emulators' pseudo-terminals in tests, or
already built transports (an SDK ``PortHandler``, a serial-like object) for the in-process path,
so tests run exactly this code. The clock is a parameter too (:class:`SystemClock` on hardware).

When a port cannot be opened the error (:class:`HardwareError`) names the port and says what to
do: plug it in, join the ``dialout`` group (the wording of ``sensor.ports``, which the drivers
use too), close the program that holds it.
"""

from __future__ import annotations

import contextlib
import errno
import logging
import os
import signal
import threading
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from types import FrameType
from typing import Any

from palpate.config.schema import StackConfig
from palpate.robot.drive import DriveController
from palpate.robot.dynamixel.driver import DynamixelBus
from palpate.robot.motors import ServoFaultError, ServoTransportError
from palpate.robot.xystage import StageController
from palpate.sensor.clock import Clock, SystemClock
from palpate.sensor.ports import DIALOUT_HINT, os_errno
from palpate.sensor.reader import FrameReader, SensorPortError, SerialLike

log = logging.getLogger(__name__)

SIM_PORT = "sim"
LIST_PORTS = "python -m serial.tools.list_ports"


class HardwareError(OSError):
    """A bench port cannot be opened or does not answer; the message names it and the remedy."""


class Terminated(BaseException):  # like KeyboardInterrupt, not an error
    """SIGTERM or SIGHUP arrived: unwind (torque off, logs closed) and exit."""


@dataclass
class Hardware:
    """The opened bench: the drive (homed, torque on), the FBG frame reader and the clock."""

    drive: DriveController
    reader: FrameReader
    clock: Clock
    stage: StageController | None = None  # the x-y stage under the sample, when the robot has one


def port_problem(port: str, role: str, key: str) -> str | None:
    """What is wrong with a device path before opening it, or None (also for pyserial URLs).

    ``role`` is what the port is for ("servo bus"), ``key`` where it is configured.
    """
    if port == SIM_PORT:
        return (
            f"{role} port is {SIM_PORT!r} (the simulator): name the device in {key}, "
            f"e.g. /dev/ttyUSB0 (list the ports with `{LIST_PORTS}`)"
        )
    if "://" in port:
        return None
    if not os.path.exists(port):
        return _hint(errno.ENOENT, port, role, key)
    if not os.access(port, os.R_OK | os.W_OK):
        return _hint(errno.EACCES, port, role, key)
    return None


def _hint(code: int | None, port: str, role: str, key: str) -> str:
    if code == errno.ENOENT:
        return (
            f"{role} port {port}: no such device. Is it plugged in and powered? List the serial "
            f"ports with `{LIST_PORTS}` and set {key}"
        )
    if code in (errno.EACCES, errno.EPERM):
        return f"{role} port {port}: {DIALOUT_HINT}"
    if code == errno.EBUSY:
        return (
            f"{role} port {port}: busy. Another program holds it (Dynamixel Wizard, a serial "
            "monitor, another palpate): close it and try again"
        )
    return f"{role} port {port}: cannot open it"


def explain(exc: BaseException, port: str, role: str, key: str) -> HardwareError:
    """A :class:`HardwareError` for a failed open or a silent bus, with the remedy."""
    code = os_errno(exc)
    if code in (errno.EACCES, errno.EPERM):
        return HardwareError(_hint(code, port, role, key))  # the driver's text repeats the hint
    if code is not None:
        return HardwareError(f"{_hint(code, port, role, key)} ({exc})")
    if isinstance(exc, ServoTransportError) and not str(exc).startswith("cannot open"):
        return HardwareError(
            f"{role} port {port} opened but the servos do not answer ({exc}). Check the servo "
            "power supply, the cable, the IDs and the baud rate (servos.* of the robot file)"
        )
    return HardwareError(f"{role} port {port}: {exc}")


def _name(port: str | Any) -> str:
    if isinstance(port, str):
        return port
    getter = getattr(port, "getPortName", None)
    return str(getter() if callable(getter) else getattr(port, "name", port))


START_ATTEMPTS = 3
"""Times the servos' start (ping, profiles, present pose, torque) is tried before the bus is
called silent: each write already has ``servos.retries``, but a host busy beside the bus can
leave a USB adapter's (or the emulator's) answers unread for longer than those take (80 ms at
the default 20 ms timeout); the rehearsal beside two spinning cores once failed so at open."""


def _start(drive: DriveController) -> None:
    """``drive.start()``, tried :data:`START_ATTEMPTS` times (it is repeatable: it homes at the
    present pose) before its last transport error is raised."""
    for attempt in range(START_ATTEMPTS):
        try:
            drive.start()
            return
        except ServoTransportError:
            if attempt == START_ATTEMPTS - 1:
                raise


@contextlib.contextmanager
def open_hardware(
    stack: StackConfig,
    *,
    servo_port: str | Any | None = None,
    board_port: str | SerialLike | None = None,
    clock: Clock | None = None,
    servo_key: str = "servos.port",
    board_key: str = "board.port",
) -> Iterator[Hardware]:
    """Open the board, then the servo bus (homed at the present pose, torque on; the x-y stage
    too when the robot has one); yield them.

    Ports default to ``stack.servos.port`` and ``stack.board.port``. ``servo_key`` and
    ``board_key`` say where the ports are configured, for the messages. Raises
    :class:`HardwareError` if a port cannot be opened or the servos do not answer.
    """
    sp = stack.servos.port if servo_port is None else servo_port
    bp = stack.board.port if board_port is None else board_port
    clock = clock if clock is not None else SystemClock()
    for port, role, key in ((bp, "acquisition board", board_key), (sp, "servo bus", servo_key)):
        if isinstance(port, str) and (problem := port_problem(port, role, key)):
            raise HardwareError(problem)
    try:
        reader = FrameReader.from_config(bp, stack.sensor, stack.board, clock=clock)
    except SensorPortError as exc:
        raise explain(exc, _name(bp), "acquisition board", board_key) from exc
    try:
        bus = DynamixelBus.from_config(stack.servos, port=sp, stage=stack.stage)
        drive = DriveController(bus, stack.drive)
        stage = None if stack.stage is None else StageController(bus, stack.stage)
        try:
            _start(drive)
            if stage is not None:
                stage.start()
        except ServoTransportError as exc:
            drive.close()
            raise explain(exc, _name(sp), "servo bus", servo_key) from exc
        except BaseException:
            drive.close()
            raise
        try:
            yield Hardware(drive, reader, clock, stage)
        finally:
            drive.close()  # torque off on every servo, then the port is released
    finally:
        reader.close()


@contextlib.contextmanager
def terminate_as_interrupt() -> Iterator[None]:
    """Turn SIGTERM and SIGHUP into :class:`Terminated` while inside, so ``finally`` blocks run
    (torque off) when the process is killed or its terminal closes. No-op off the main thread."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum: int, frame: FrameType | None) -> None:
        raise Terminated(signal.Signals(signum).name)

    previous = {s: signal.signal(s, handler) for s in (signal.SIGTERM, signal.SIGHUP)}
    try:
        yield
    finally:
        for s, h in previous.items():
            signal.signal(s, h)


def run_on_hardware(command: str, body: Callable[[], int], *, stopped_exit: int = 1) -> int:
    """Run ``body`` (which opens the bench) with SIGTERM/SIGHUP as interrupts, and turn what
    can go wrong with the hardware into a message on stderr and an exit code: 1 when a port
    cannot be opened or a servo or stream fails, ``stopped_exit`` when interrupted. Torque is
    already off by then: ``open_hardware`` released it on the way out."""
    try:
        with terminate_as_interrupt():
            return body()
    except HardwareError as exc:
        log.error("palpate %s: %s", command, exc)
        return 1
    except (ServoTransportError, ServoFaultError, SensorPortError) as exc:
        log.error("palpate %s: hardware fault, torque off: %s", command, exc)
        return 1
    except (KeyboardInterrupt, Terminated) as exc:
        log.warning("palpate %s: stopped (%s), torque off", command, type(exc).__name__)
        return stopped_exit
