"""Teleop over ROS 2: a gamepad through the ``joy`` node (``sensor_msgs/Joy`` on ``joy``) jogs the
robot in real time, through the jog model ``palpate teleop`` uses (the same guards, limits and
emergency stop: ``robot.teleop``).

The first command opens a jog session (the robot: in simulation the scene's bench twin, its
sample in front) and holds the node's robot, so no trial starts meanwhile; each tick takes the
commands that came since the last, and when none came for ``COMMAND_TIMEOUT_S`` the robot holds
where it is. After ``IDLE_S`` without a command the session ends, torque off, and trials may
run again. The ticks go to the node's topics as a trial's do::

    jog = RemoteJog(runner, view, busy)
    jog.joy(message)          # a Joy message: its sticks and buttons as keys
    jog.estop()               # the stop service while jogging
    jog.close()               # the node's shutdown: torque off
"""

from __future__ import annotations

import contextlib
import dataclasses
import logging
import math
import threading
import time
from typing import Protocol

from sensor_msgs.msg import Joy

from palpate.config.scene import CampaignConfig
from palpate.config.schema import StackConfig
from palpate.estimation.beam.stage import Stage
from palpate.lab.hardware import Hardware
from palpate.lab.jog import jog_session, jog_tick
from palpate.robot.indentation import State
from palpate.robot.teleop import ESTOP_KEY
from palpate.robot.teleop.remote import JoyMapping, hold

from .view import RosView

log = logging.getLogger(__name__)

JOG_RATE_HZ = 100.0  # control ticks per second of wall time
COMMAND_TIMEOUT_S = 0.5  # no command for this long: the robot holds where it is
IDLE_S = 10.0  # no command for this long (and nothing moving): the session ends, torque off


class JogRobot(Protocol):
    """What a jog session needs of the runner (``palpate.ros.runner.SimRunner``)."""

    stack: StackConfig

    @property
    def campaign_config(self) -> CampaignConfig: ...

    def jog_hardware(self) -> contextlib.AbstractContextManager[Hardware]: ...


@dataclasses.dataclass
class _Commands:
    """What came since the last tick (under the lock)."""

    keys: list[str] = dataclasses.field(default_factory=list)
    last: float = -math.inf  # time.monotonic() of the last command


class RemoteJog:
    """The node's teleop (see the module docstring); ``busy`` is the node's lock on the robot."""

    def __init__(self, robot: JogRobot, view: RosView, busy: threading.Lock) -> None:
        self.robot, self.view, self.busy = robot, view, busy
        self.pad = JoyMapping()
        self.lock = threading.Lock()
        self.commands = _Commands()
        self.closing = threading.Event()
        self.thread: threading.Thread | None = None

    @property
    def active(self) -> bool:
        return self.thread is not None and self.thread.is_alive()

    def joy(self, message: Joy) -> None:
        keys = self.pad.keys(list(message.axes), list(message.buttons))
        self._command(keys)

    def estop(self) -> None:
        """The emergency stop: retract to home and hold, until re-armed (button B)."""
        self._command([ESTOP_KEY])

    def close(self) -> None:
        self.closing.set()
        if self.thread is not None and self.thread.ident is not None:  # started
            self.thread.join()

    def _command(self, keys: list[str]) -> None:
        with self.lock:
            self.commands.keys.extend(keys)
            self.commands.last = time.monotonic()
        if self.active or self.closing.is_set():
            return
        if not self.busy.acquire(blocking=False):
            log.warning("palpate ros: a trial or survey holds the robot; the jog is ignored")
            return
        self.thread = threading.Thread(target=self._session, name="palpate-ros-jog")
        self.thread.start()

    def _take(self) -> _Commands:
        with self.lock:
            taken = self.commands
            self.commands = _Commands(last=taken.last)
        return taken

    def _session(self) -> None:
        try:
            with self.robot.jog_hardware() as hw:
                self._run(hw)
        except Exception:
            log.exception("palpate ros: the jog session failed (torque off)")
        finally:
            self.busy.release()

    def _run(self, hw: Hardware) -> None:
        tick = 1.0 / JOG_RATE_HZ
        model, rig = jog_session(self.robot.stack, self.robot.campaign_config, hw, tick)
        publish = self.view.trial(Stage.on(model.tube, 0.0))
        t0, recovered, next_tick = hw.clock.now(), False, hw.clock.now()
        try:
            while not self.closing.is_set():
                got = self._take()
                quiet = time.monotonic() - got.last
                for key in got.keys:
                    effect = model.press(key)
                    if effect is not None and effect.kind == "recover":  # re-armed after a fault
                        recovered = False
                        if not rig.recover():
                            model.fail("could not clear the servo fault: power-cycle the servos")
                if quiet >= COMMAND_TIMEOUT_S:
                    hold(model, f"no command for {COMMAND_TIMEOUT_S:g} s")
                    if quiet >= IDLE_S and model.state in (State.IDLE, State.ABORTED):
                        break
                obs, recovered = jog_tick(model, rig, hw.clock, recovered)
                publish(dataclasses.replace(obs, t=obs.t - t0), model.state)
                next_tick = max(next_tick + tick, hw.clock.now())
                hw.clock.sleep(next_tick - hw.clock.now())
        finally:
            rig.release()


__all__ = ["COMMAND_TIMEOUT_S", "IDLE_S", "JogRobot", "RemoteJog"]
