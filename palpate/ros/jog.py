"""Teleop over ROS 2: a gamepad through the ``joy`` node (``sensor_msgs/Joy`` on ``joy``), or a
lab's own controller streaming joint goals (CRTK ``servo_jp``, ``sensor_msgs/JointState``),
jogs the robot in real time through the jog model ``palpate teleop`` uses (the same guards,
limits and emergency stop: ``robot.teleop``).

The first command opens a jog session (the robot: in simulation the scene's bench twin, its
sample in front; on the bench the node's open hardware), zeroes the strains with the sensor
free, and holds the node's robot, so no trial starts meanwhile; each tick takes the commands
that came since the last, and when none came for ``COMMAND_TIMEOUT_S`` (a client gone quiet or
disconnected) the robot holds where it is. After ``IDLE_S`` without a command the session
ends, torque off, and trials may run again. The ticks go to the node's topics as a trial's do::

    jog = RemoteJog(runner, view, busy)
    jog.joy(message)          # a Joy message: its sticks and buttons as keys
    jog.servo_jp(message)     # a JointState: the goal (within a step of where the robot is)
    ok, answer = jog.zero()   # re-zero the strains now (the sensor free), its baseline as JSON
    jog.estop()               # the stop service while jogging
    jog.close()               # the node's shutdown: torque off
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import logging
import math
import threading
import time
from typing import Protocol

from sensor_msgs.msg import JointState, Joy

from palpate.config.scene import CampaignConfig
from palpate.config.schema import StackConfig
from palpate.estimation.beam.stage import Stage
from palpate.lab.hardware import Hardware
from palpate.lab.jog import jog_session, jog_tick
from palpate.robot.indentation import State
from palpate.robot.records.ros2 import JOINTS
from palpate.robot.rig import ServoFbgRig
from palpate.robot.teleop import ESTOP_KEY, Teleop
from palpate.robot.teleop.remote import JoyMapping, hold, servo_to
from palpate.robot.trial.setup import detector_for
from palpate.sensor.strain import StrainChain

from .view import RosView

log = logging.getLogger(__name__)

JOG_RATE_HZ = 100.0  # control ticks per second of wall time
COMMAND_TIMEOUT_S = 0.5  # no command for this long: the robot holds where it is
IDLE_S = 10.0  # no command for this long (and nothing moving): the session ends, torque off
ZERO_WAIT_S = 60.0  # wall time a zero request waits for the session to take it


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
    goal: tuple[float | None, float | None] | None = None  # servo_jp's newest: advance, roll
    zero: list[_Zero] = dataclasses.field(default_factory=list)  # re-zero requests waiting
    last: float = -math.inf  # time.monotonic() of the last command


@dataclasses.dataclass
class _Zero:
    """A re-zero request: set when answered (ok, the answer)."""

    done: threading.Event = dataclasses.field(default_factory=threading.Event)
    answer: tuple[bool, str] = (False, "the jog session ended before zeroing")

    def reply(self, ok: bool, answer: str) -> None:
        self.answer = (ok, answer)
        self.done.set()


class RemoteJog:
    """The node's teleop (see the module docstring); ``busy`` is the node's lock on the robot."""

    def __init__(self, robot: JogRobot, view: RosView, busy: threading.Lock) -> None:
        self.robot, self.view, self.busy = robot, view, busy
        self.pad = JoyMapping()
        self.lock = threading.Lock()
        self.starting = threading.Lock()  # one caller at a time decides to open a session
        self.commands = _Commands()
        self.closing = threading.Event()
        self.thread: threading.Thread | None = None

    @property
    def active(self) -> bool:
        return self.thread is not None and self.thread.is_alive()

    def joy(self, message: Joy) -> None:
        keys = self.pad.keys(list(message.axes), list(message.buttons))
        self._command(keys)

    def servo_jp(self, message: JointState) -> None:
        """CRTK ``servo_jp``: a joint goal by name (``stage_translation`` m, ``outer_roll``
        rad; unnamed: in that order), met within a step of where the robot is each tick."""
        names = list(message.name) or JOINTS[: len(message.position)]
        goal = dict(zip(names, (float(p) for p in message.position), strict=False))
        unknown = set(goal) - set(JOINTS)
        if unknown:
            log.warning("palpate ros: servo_jp: no joint %s (%s)", sorted(unknown), JOINTS)
            return
        with self.lock:
            self.commands.goal = (goal.get(JOINTS[0]), goal.get(JOINTS[1]))
        self._command([])

    def zero(self) -> tuple[bool, str]:
        """Re-zero the strains with the sensor free (a session opens if none is: its start
        zeroes); the baseline's wavelengths as JSON, or why not."""
        request = _Zero()
        with self.lock:
            self.commands.zero.append(request)
        if not self._command([]):
            return False, "busy: a trial or survey holds the robot"
        if not request.done.wait(ZERO_WAIT_S):
            return False, f"no zero within {ZERO_WAIT_S:g} s"
        return request.answer

    def estop(self) -> None:
        """The emergency stop: retract to home and hold, until re-armed (button B)."""
        self._command([ESTOP_KEY])

    def close(self) -> None:
        self.closing.set()
        if self.thread is not None and self.thread.ident is not None:  # started
            self.thread.join()

    def _command(self, keys: list[str]) -> bool:
        """Queue ``keys`` (and what the caller queued) for the session, opening one if none
        runs; False when a trial or survey holds the robot (the commands are dropped)."""
        with self.lock:
            self.commands.keys.extend(keys)
            self.commands.last = time.monotonic()
        # callbacks run on several threads: two that both saw no session would both try to
        # open one, and the loser would drop the winner's commands as "busy"
        with self.starting:
            if self.active or self.closing.is_set():
                return True
            if not self.busy.acquire(blocking=False):
                log.warning("palpate ros: a trial or survey holds the robot; the jog is ignored")
                self._take()
                return False
            self.thread = threading.Thread(target=self._session, name="palpate-ros-jog")
            self.thread.start()
        return True

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
            for request in self._take().zero:  # their answer says the session ended
                request.done.set()
            self.busy.release()

    def _run(self, hw: Hardware) -> None:
        tick = 1.0 / JOG_RATE_HZ
        model, rig = jog_session(self.robot.stack, self.robot.campaign_config, hw, tick)
        zeroed: StrainChain | None = rig.chain  # the session's start zeroed the strains
        publish = self.view.trial(Stage.on(model.tube, 0.0))
        t0, recovered, next_tick = hw.clock.now(), False, hw.clock.now()
        moved = False  # a session opened only to zero ends once it has answered
        try:
            while not self.closing.is_set():
                got = self._take()
                self._zero(got.zero, model, rig, zeroed)
                zeroed = None  # the start's zero answers what came before the first tick only
                moved = moved or bool(got.keys) or got.goal is not None
                if got.zero and not moved:
                    break
                if got.goal is not None:
                    servo_to(model, *got.goal)
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

    def _zero(
        self, requests: list[_Zero], model: Teleop, rig: ServoFbgRig, zeroed: StrainChain | None
    ) -> None:
        """Answer ``requests``: with the zero the session's start took (``zeroed``), or a new
        one taken now if the sensor is free and still."""
        if not requests:
            return
        obs = model.obs
        still = model.state in (State.IDLE, State.ABORTED)
        if zeroed is None and not (still and obs is not None and not obs.contact):
            for request in requests:
                request.reply(False, f"not free and still ({model.state.value}): retract first")
            return
        if zeroed is None:
            zeroed = rig.zero()
            model.detector = detector_for(self.robot.campaign_config, zeroed)
        answer = json.dumps(_baseline(zeroed))
        for request in requests:
            request.reply(True, answer)


def _baseline(chain: StrainChain) -> dict[str, object]:
    """The zero's facts for the answer: the wavelengths at rest and their noise (m)."""
    b = chain.baseline
    assert b is not None, "the rig zeroes its chain"
    return {
        "zero_wavelengths_m": [float(w) for w in b.wavelengths],
        "noise_m": [float(n) for n in b.noise],
        "reference_m": b.reference,
        "samples": b.samples,
    }


__all__ = ["COMMAND_TIMEOUT_S", "IDLE_S", "ZERO_WAIT_S", "JogRobot", "RemoteJog"]
