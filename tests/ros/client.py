"""A ROS 2 client in its own process, as a lab's software is: it subscribes to every topic of
``palpate ros``, calls its services in order and prints what it saw as one JSON line.

    python tests/ros/client.py --namespace palpate run_trial stop ...

Each service name is called once, in order; ``stop@N`` calls ``stop`` once the trial has
published N joint states (a trial under way), while the previous call is still running
(``ready@N`` prints ``under way`` then instead of calling anything); ``result`` waits for the
last trial's latched ``trial/result`` and answers with it;
``name=value`` sets the node's parameter (an integer when it reads as one); ``joy`` holds a
gamepad's stick forward until the robot has advanced 1 mm, then goes quiet for 2 s of the
node's clock, and until the robot has stood still for ``STILL_S`` of it, while the joint
states are recorded (``jogs``); ``servo`` does the same with CRTK
``servo_jp`` goals (an empty one first: it opens the jog session, whose joint states then flow).
"""

from __future__ import annotations

import argparse
import atexit
import itertools
import json
import math
import os
import signal
import threading
import time
from collections import Counter, defaultdict
from typing import Any

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

import rclpy
from rclpy.executors import MultiThreadedExecutor
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient
from rclpy.qos import DurabilityPolicy, QoSProfile
from rclpy.signals import SignalHandlerOptions
from sensor_msgs.msg import JointState, Joy
from std_srvs.srv import Trigger

from palpate.ros.names import SERVICES, TOPICS

JOY_HZ = 20.0  # the joy node's repeat rate while a stick is held
STILL_S = 1.0  # s of the node's clock a quiet jog's robot must stand still for
WAIT_S = float(
    os.environ.get("CLIENT_WAIT_S", "600")
)  # wall time for a service to appear and answer (a busy machine)


def message_type(name: str) -> Any:
    package, _, kind = name.split("/")
    module = __import__(f"{package}.msg", fromlist=[kind])
    return getattr(module, kind)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--namespace", default="palpate")
    parser.add_argument("calls", nargs="*")
    args = parser.parse_args()
    # SIGTERM (a caller terminated mid-trial) leaves the DDS graph in order: rclpy's own handler
    # passes the signal on at once, and the process could end before its participant's
    # removal was sent; the node would then see it gone only at the lease's end (20 s)
    rclpy.init(signal_handler_options=SignalHandlerOptions.SIGINT)
    signal.signal(signal.SIGTERM, _leave)
    node = rclpy.create_node("palpate_test_client")
    ns = "/" + args.namespace
    counts: Counter[str] = Counter()
    stamps: dict[str, list[float]] = defaultdict(list)
    last: dict[str, Any] = {}
    states: list[str] = []
    pushes: list[float] = []
    joints: list[tuple[float, float]] = []  # (stamp s, advance m) of every joint state
    lock = threading.Condition()  # every message and every answer notifies its waiters

    def subscriber(topic: str, kind: str) -> None:
        latched = topic.startswith(("trial/", "map/"))
        qos = QoSProfile(
            depth=1000,
            durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE,
        )

        def seen(message: Any) -> None:
            with lock:
                counts[topic] += 1
                header = getattr(message, "header", None)
                if header is not None:
                    stamps[topic].append(header.stamp.sec + header.stamp.nanosec * 1e-9)
                if topic == "measured_js":
                    stamp = message.header.stamp
                    joints.append((stamp.sec + stamp.nanosec * 1e-9, message.position[0]))
                if topic == "measured_cf" and math.isfinite(message.wrench.force.z):
                    pushes.append(message.wrench.force.z)
                if topic == "trial/state":
                    states.append(message.data)
                last[topic] = message
                lock.notify_all()

        name = topic if topic.startswith("/") else f"{ns}/{topic}"
        node.create_subscription(message_type(kind), name, seen, qos)

    for topic, (kind, _) in TOPICS.items():
        subscriber(topic, kind)
    clients: dict[str, Any] = {}  # made when first called: a client is a caller in the graph
    executor = MultiThreadedExecutor(num_threads=2)
    executor.add_node(node)
    spinning = threading.Thread(target=executor.spin)
    spinning.start()

    def teardown() -> None:  # once: at the end, or on the way out of a SIGTERM
        atexit.unregister(teardown)
        executor.shutdown()
        spinning.join()  # DDS's threads end before the interpreter's exit, not during it
        node.destroy_node()
        rclpy.shutdown()

    atexit.register(teardown)
    answers: list[dict[str, Any]] = []
    pending: list[Any] = []
    parameters = AsyncParameterClient(node, f"{ns}/palpate")
    joy = node.create_publisher(Joy, f"{ns}/joy", 10)
    servo_jp = node.create_publisher(JointState, f"{ns}/servo_jp", 10)

    def command(how: str, start: float | None) -> None:
        if how == "joy":  # a held stick
            joy.publish(Joy(axes=[0.0, 1.0], buttons=[0, 0]))
        elif start is None:  # no reading yet: an empty goal opens the session
            servo_jp.publish(JointState())
        else:
            servo_jp.publish(JointState(name=["stage_translation"], position=[start + 1e-3]))

    def jog(how: str) -> dict[str, Any]:
        """Hold the stick forward (or stream the goal 1 mm on) until the robot has advanced
        1 mm, then go quiet for 2 s of its clock."""
        deadline = time.monotonic() + WAIT_S
        start: float | None = None

        def advanced() -> bool:
            return start is not None and joints[-1][1] >= start + 1e-3 - 20e-6

        with lock:
            while time.monotonic() < deadline:
                command(how, start)  # 20 a second, as the joy node repeats
                if lock.wait_for(advanced, timeout=1.0 / JOY_HZ):
                    break
                if start is None and joints:
                    start = joints[-1][1]
            quiet_from, stopped_at = len(joints), joints[-1][0]

            def still() -> bool:  # 2 s of the node's clock, the last STILL_S of it put
                quiet = joints[quiet_from:]
                moved = [t for (_, a), (t, b) in itertools.pairwise(quiet) if a != b]
                last = max(moved, default=stopped_at)
                return joints[-1][0] > max(stopped_at + 2.0, last + STILL_S)

            lock.wait_for(still, timeout=WAIT_S)
            return {"start": start, "quiet": joints[quiet_from:]}

    def answered(future: Any) -> Any:
        """A service's or parameter call's result, waited for."""
        future.add_done_callback(lambda _: notify())
        with lock:
            lock.wait_for(future.done, timeout=WAIT_S)
        return future.result()

    def notify() -> None:
        with lock:
            lock.notify_all()

    jogs: list[dict[str, Any]] = []
    for k, call in enumerate(args.calls):
        if call in ("joy", "servo"):
            jogs.append(jog(call))
            continue
        if "=" in call:
            name, _, text = call.partition("=")
            value: Any = int(text) if text.lstrip("-").isdigit() else text
            if not parameters.wait_for_services(timeout_sec=WAIT_S):
                raise SystemExit("no parameter services")
            future = parameters.set_parameters([Parameter(name, value=value)])
            [set_result] = answered(future).results
            answers.append({"call": call, "success": set_result.successful, "message": ""})
            continue
        if call == "result":  # the latched result of the last trial, once there is one
            with lock:
                lock.wait_for(lambda: "trial/result" in last, timeout=WAIT_S)
                data = last["trial/result"].data
            answers.append({"call": call, "success": True, "message": data})
            continue
        service, _, after = call.partition("@")
        if service == "ready":  # say when the running trial has published that many joints
            with lock:
                wanted = int(after)
                lock.wait_for(lambda n=wanted: counts["measured_js"] >= n, timeout=WAIT_S)
            print("under way", flush=True)
            continue
        if service not in SERVICES:
            raise SystemExit(f"no service {service} in palpate.ros.names")
        if service not in clients:
            clients[service] = node.create_client(Trigger, f"{ns}/{service}")
        client = clients[service]
        if not client.wait_for_service(timeout_sec=WAIT_S):
            raise SystemExit(f"no service {service}")
        if after:
            with lock:
                wanted = int(after)
                lock.wait_for(lambda n=wanted: counts["measured_js"] >= n, timeout=WAIT_S)
        future = client.call_async(Trigger.Request())
        pending.append((call, future))
        if k + 1 < len(args.calls) and "@" in args.calls[k + 1]:
            continue  # the next call comes while this one runs: do not wait for it yet
        for name, f in pending:
            result = answered(f)
            answers.append({"call": name, "success": result.success, "message": result.message})
        pending.clear()
    rows = [json.loads(a["message"]) for a in answers if a["message"].startswith("{")]
    ended = [r["state"] for r in rows if "state" in r]

    def delivered() -> bool:  # DDS delivers asynchronously: each trial's result and last state
        return counts["trial/result"] >= len(ended) and (not ended or states[-1:] == ended[-1:])

    with lock:
        lock.wait_for(delivered, timeout=WAIT_S)
        out = {
            "answers": answers,
            "jogs": jogs,
            "counts": dict(counts),
            "states": states,
            "stamps": dict(stamps.items()),
            "result": last["trial/result"].data if "trial/result" in last else None,
            "strongest_push_n": min(pushes, default=None),  # +z into the tissue: most negative
        }
    print(json.dumps(out))
    teardown()


def _leave(signum: int, frame: Any) -> None:
    """SIGTERM: out through ``SystemExit``, whose way out tears the node down."""
    raise SystemExit(128 + signum)


if __name__ == "__main__":
    main()
