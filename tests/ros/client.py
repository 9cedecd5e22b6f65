"""A ROS 2 client in its own process, as a lab's software is: it subscribes to every topic of
``palpate ros``, calls its services in order and prints what it saw as one JSON line.

    python tests/ros/client.py --namespace palpate run_trial stop ...

Each service name is called once, in order; ``stop@N`` calls ``stop`` once the trial has
published N joint states (a trial under way), while the previous call is still running.
"""

from __future__ import annotations

import argparse
import json
import os
import threading
import time
from collections import Counter, defaultdict
from typing import Any

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

import rclpy  # noqa: E402
from rclpy.executors import MultiThreadedExecutor  # noqa: E402
from rclpy.qos import DurabilityPolicy, QoSProfile  # noqa: E402
from std_srvs.srv import Trigger  # noqa: E402

from palpate.ros.names import SERVICES, TOPICS  # noqa: E402

WAIT_S = 600.0  # wall time for a service to appear and answer (a busy machine)


def message_type(name: str) -> Any:
    package, _, kind = name.split("/")
    module = __import__(f"{package}.msg", fromlist=[kind])
    return getattr(module, kind)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--namespace", default="palpate")
    parser.add_argument("calls", nargs="*")
    args = parser.parse_args()
    rclpy.init()
    node = rclpy.create_node("palpate_test_client")
    ns = "/" + args.namespace
    counts: Counter[str] = Counter()
    stamps: dict[str, list[float]] = defaultdict(list)
    last: dict[str, Any] = {}
    states: list[str] = []
    lock = threading.Lock()

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
                if topic == "trial/state":
                    states.append(message.data)
                last[topic] = message

        name = topic if topic.startswith("/") else f"{ns}/{topic}"
        node.create_subscription(message_type(kind), name, seen, qos)

    for topic, (kind, _) in TOPICS.items():
        subscriber(topic, kind)
    clients = {s: node.create_client(Trigger, f"{ns}/{s}") for s in SERVICES}
    executor = MultiThreadedExecutor(num_threads=2)
    executor.add_node(node)
    threading.Thread(target=executor.spin, daemon=True).start()
    answers: list[dict[str, Any]] = []
    pending: list[Any] = []
    for call in args.calls:
        service, _, after = call.partition("@")
        client = clients[service]
        if not client.wait_for_service(timeout_sec=WAIT_S):
            raise SystemExit(f"no service {service}")
        if after:
            deadline = time.monotonic() + WAIT_S
            while counts["measured_js"] < int(after) and time.monotonic() < deadline:
                time.sleep(0.01)
        future = client.call_async(Trigger.Request())
        pending.append((call, future))
        if not after and call != args.calls[-1] and "@" in args.calls[args.calls.index(call) + 1]:
            continue  # the next call interrupts this one: do not wait for it
        for name, f in pending:
            deadline = time.monotonic() + WAIT_S
            while not f.done() and time.monotonic() < deadline:
                time.sleep(0.01)
            result = f.result()
            answers.append({"call": name, "success": result.success, "message": result.message})
        pending.clear()
    time.sleep(0.5)  # the last messages in flight (DDS delivers asynchronously)
    with lock:
        cf = last.get("measured_cf")
        out = {
            "answers": answers,
            "counts": dict(counts),
            "states": states,
            "stamps": {k: v for k, v in stamps.items()},
            "result": last["trial/result"].data if "trial/result" in last else None,
            "last_force_z": None if cf is None else cf.wrench.force.z,
        }
    print(json.dumps(out))
    executor.shutdown()
    node.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
