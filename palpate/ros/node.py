"""The ROS 2 node: the topics of :mod:`palpate.ros.view`, the services of :mod:`palpate.ros.names`,
on rclpy with a context of its own (a program may hold other nodes).

On this machine only unless asked: before its context starts, the node sets
``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`` (ROS 2 Iron and later), so DDS discovery and
traffic stay on the loopback; ``network=True`` (``palpate ros --network``) leaves the range to
the environment, for a lab that opens the robot to its network on purpose::

    node = PalpateNode(SimRunner(Path("config/scenes/robot.yaml")), rate=50.0)
    node.spin()          # until Ctrl-C or SIGTERM: a running trial stops, retracts, logs its end
    node.close()

A service that runs a trial answers when the trial has ended; ``stop`` answers at once, and
the running trial retracts from its next control tick, as it does when its caller leaves the
ROS graph (the service has no client left). Only one trial or survey runs at a time
(a second request while one runs is refused, not queued).
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import threading
import time
from typing import Any, Protocol

import rclpy
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup, ReentrantCallbackGroup
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.parameter import Parameter
from rclpy.signals import SignalHandlerOptions
from sensor_msgs.msg import JointState, Joy
from std_srvs.srv import Trigger

from palpate.config import InputError
from palpate.config.scene import CampaignConfig
from palpate.config.schema import StackConfig
from palpate.lab.hardware import Hardware
from palpate.live import View

from .jog import RemoteJog
from .view import RosView

log = logging.getLogger(__name__)

LOCALHOST = {"ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
SHUTDOWN_WAIT_S = 120.0  # wall time a running trial has to retract and close its log
CALLER_CHECK_S = 0.5  # wall time between looks for a running trial's caller in the ROS graph


class Runner(Protocol):
    """What the node runs (``palpate.ros.runner``: ``SimRunner``, ``BenchRunner``); its trials
    are the runner's own (a simulated ``TrialSpec``, a ``BenchTrial``), named by ``trial_id``."""

    simulated: bool
    stack: StackConfig

    @property
    def label(self) -> str: ...

    @property
    def campaign_config(self) -> CampaignConfig: ...

    def jog_hardware(self) -> contextlib.AbstractContextManager[Hardware]: ...

    def spec(self, which: str) -> Any: ...

    def run(self, spec: Any, view: View, stop: Any) -> Any: ...

    def survey(self, view: View, max_probes: int | None) -> Any: ...


class PalpateNode:
    """The node ``palpate`` in ``namespace``, its topics at ``rate`` per second of the trial's
    clock, serving ``runner``'s trials; a simulated trial at ``pace`` times real time (None: as
    fast as it computes)."""

    def __init__(
        self,
        runner: Runner,
        *,
        namespace: str = "palpate",
        rate: float = 50.0,
        network: bool = False,
        pace: float | None = None,
    ) -> None:
        if not network:
            os.environ.update(LOCALHOST)
        self.runner = runner
        self.context = rclpy.Context()
        # the command handles SIGINT and SIGTERM itself: a running trial retracts first
        rclpy.init(args=[], context=self.context, signal_handler_options=SignalHandlerOptions.NO)
        self.node = rclpy.create_node("palpate", namespace=namespace, context=self.context)
        self.node.declare_parameter("trial", "")
        self.node.declare_parameter("max_probes", 0)
        self.view = RosView(
            self.node, runner.stack, rate=rate, sim_time=runner.simulated, pace=pace
        )
        self.stopping = threading.Event()
        self.busy = threading.Lock()
        work, quick = MutuallyExclusiveCallbackGroup(), ReentrantCallbackGroup()
        serve = self.node.create_service
        serve(Trigger, "run_trial", self._run_trial, callback_group=work)
        serve(Trigger, "run_survey", self._run_survey, callback_group=work)
        serve(Trigger, "stop", self._stop, callback_group=quick)
        serve(Trigger, "zero", self._zero, callback_group=quick)
        self.jog = RemoteJog(runner, self.view, self.busy)
        listen = self.node.create_subscription
        listen(Joy, "joy", self.jog.joy, 10, callback_group=quick)
        listen(JointState, "servo_jp", self.jog.servo_jp, 10, callback_group=quick)
        self.executor = MultiThreadedExecutor(num_threads=3, context=self.context)
        self.executor.add_node(self.node)
        self.running: str | None = None  # the trial running now (its id)
        self._worker: threading.Thread | None = None  # the executor's thread while it spins
        self._closed = False

    @property
    def name(self) -> str:
        return str(self.node.get_fully_qualified_name())

    def spin(self) -> None:
        """Serve until the context shuts down or the caller is interrupted (KeyboardInterrupt,
        ``palpate.lab.hardware.Terminated``): then a running trial is told to stop. The
        executor spins in a thread of its own; this one waits where a signal reaches it."""
        # not Thread.join here: a signal that interrupts it marks the thread ended on Python 3.11
        ended = threading.Event()
        worker = self._worker = threading.Thread(
            target=self._spin, args=(ended,), name="palpate-ros"
        )
        worker.start()
        try:
            while not ended.wait(timeout=1.0):
                pass
        except BaseException:
            self.stopping.set()
            raise

    def _spin(self, ended: threading.Event) -> None:
        try:
            with contextlib.suppress(ExternalShutdownException):
                self.executor.spin()
        finally:
            ended.set()

    def close(self) -> None:
        """Stop a running trial (it retracts and closes its log), then the executor, the node
        and the context (idempotent)."""
        if self._closed:
            return
        self._closed = True
        self.stopping.set()
        self.jog.close()  # torque off
        self.executor.shutdown(timeout_sec=SHUTDOWN_WAIT_S)
        if self._worker is not None and self._worker.ident is not None:  # started (a signal
            self._worker.join(timeout=SHUTDOWN_WAIT_S)  # may come before): ends with the executor
        self.node.destroy_node()
        if self.context.ok():
            rclpy.shutdown(context=self.context)
        # DDS's threads end here, not at the interpreter's exit (where their order is not ours)
        self.context.destroy()

    # -- services -----------------------------------------------------------------------------
    def _run_trial(self, _: Trigger.Request, response: Trigger.Response) -> Trigger.Response:
        which = str(self.node.get_parameter("trial").value)
        return self._exclusive(response, lambda: self._trial(which))

    def _trial(self, which: str) -> tuple[bool, str]:
        spec = self.runner.spec(which)
        if which:  # a named trial runs once; the next request runs the next one in order
            self.node.set_parameters([Parameter("trial", value="")])
        self.running = spec.trial_id
        try:
            outcome = self.runner.run(spec, self.view, CallerWatch(self, "run_trial"))
        finally:
            self.running = None
        row = json.dumps(outcome.as_dict(), default=_plain)
        self.view.finished(row)
        return outcome.state in ("done", "unreachable"), row

    def _run_survey(self, _: Trigger.Request, response: Trigger.Response) -> Trigger.Response:
        def survey() -> tuple[bool, str]:
            most = int(self.node.get_parameter("max_probes").value)
            result = self.runner.survey(self.view, most or None)
            return True, json.dumps(result.as_dict(), default=_plain)

        return self._exclusive(response, survey)

    def _exclusive(self, response: Trigger.Response, work: Any) -> Trigger.Response:
        """Run ``work`` (-> success, message) unless something runs already; bad input is an
        answer (success False, the message), a bug is logged with its traceback."""
        if not self.busy.acquire(blocking=False):
            holder = "teleop" if self.jog.active else self.running or "a survey"
            response.success, response.message = False, f"busy: {holder} runs"
            return response
        try:
            self.stopping.clear()
            response.success, response.message = work()
        except InputError as exc:
            response.success, response.message = False, str(exc)
        except Exception as exc:
            log.exception("palpate ros: internal error")
            response.success, response.message = False, f"internal error: {exc!r}"
        finally:
            self.busy.release()
        return response

    def _zero(self, _: Trigger.Request, response: Trigger.Response) -> Trigger.Response:
        response.success, response.message = self.jog.zero()
        return response

    def _stop(self, _: Trigger.Request, response: Trigger.Response) -> Trigger.Response:
        if self.jog.active:
            self.jog.estop()
            response.success, response.message = True, "emergency stop: retracting to home"
            return response
        running = self.running
        self.stopping.set()
        response.success = running is not None
        response.message = (
            f"stopping {running}: it retracts at its next tick"
            if running is not None
            else "no trial running"
        )
        return response


class CallerWatch:
    """A running trial's stop: the ``stop`` service, or the caller gone. The ROS graph is asked
    every ``CALLER_CHECK_S`` of wall time for the service's clients; none left (the caller
    disconnected or died) stops the trial as the stop service would."""

    def __init__(self, node: PalpateNode, service: str) -> None:
        self.node, self.service = node, service
        self.due = time.monotonic() + CALLER_CHECK_S

    def __call__(self) -> bool:
        n = self.node
        if n.stopping.is_set():
            return True
        if time.monotonic() < self.due:
            return False
        self.due = time.monotonic() + CALLER_CHECK_S
        name = f"{n.node.get_namespace().rstrip('/')}/{self.service}"
        if n.node.count_clients(name) == 0:
            log.warning("palpate ros: %s's caller left: stopping %s", self.service, n.running)
            n.stopping.set()
            return True
        return False


def _plain(value: Any) -> Any:
    """JSON for what a row may hold besides plain values (numpy scalars)."""
    if hasattr(value, "item"):
        return value.item()
    raise TypeError(f"not JSON: {type(value).__name__}")


__all__ = ["PalpateNode", "Runner"]
