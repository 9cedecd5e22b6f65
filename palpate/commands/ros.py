"""Serve the stack as a ROS 2 node: trials and surveys on request, their topics as they run.

``palpate ros`` starts the node ``/palpate/palpate`` on a simulated scene (``--scene``, no
hardware; every trial the one ``palpate sim --scene SCENE --seed SEED`` runs, so a trial started
over ROS 2 gives the same row) or on the bench (``--config BENCH_FILE``: its trials and map, as
``palpate trial`` runs them, the ports from the file or ``--servo-port``/``--board-port``). It
serves until Ctrl-C or SIGTERM; a running trial then stops, retracts and closes its log and
recording, and the bench's torque goes off. Topics, services and parameters: docs/ros2.md
(``palpate.ros.names``). DDS stays on this machine unless ``--network``.

    palpate ros --scene scenes/robot.yaml &
    python3 -c "..."   # a client: call /palpate/run_trial (std_srvs/srv/Trigger)
"""

from __future__ import annotations

import argparse
import json
import logging
import re
from datetime import datetime
from pathlib import Path
from typing import TYPE_CHECKING

from palpate.argtypes import non_negative_int, positive_float
from palpate.config import resolve
from palpate.config.loader import InputError
from palpate.lab.hardware import Terminated, terminate_as_interrupt

if TYPE_CHECKING:
    from palpate.ros.node import Runner

log = logging.getLogger(__name__)

NAMESPACE = re.compile(r"[A-Za-z][A-Za-z0-9_]*(/[A-Za-z][A-Za-z0-9_]*)*")


def register(parser: argparse.ArgumentParser) -> None:
    where = parser.add_mutually_exclusive_group()
    where.add_argument(
        "--scene",
        default=None,
        help="the simulated scene whose trials it runs (default: scenes/robot.yaml)",
    )
    where.add_argument("--config", help="a bench file: its trials and map on the hardware it names")
    parser.add_argument(
        "--servo-port", help="with --config: overrides the bench file's servos.port"
    )
    parser.add_argument("--board-port", help="with --config: overrides the bench file's board.port")
    parser.add_argument(
        "--seed", type=non_negative_int, default=0, help="the campaign's seed (as palpate sim)"
    )
    parser.add_argument(
        "--rate",
        type=positive_float,
        default=50.0,
        help="messages per second of the trial's clock on the streams (measured_js, ...)",
    )
    parser.add_argument(
        "--pace",
        type=positive_float,
        default=None,
        help="with --scene: simulated trials at PACE times real time, their streams in step "
        "with the wall clock (default: as fast as they compute)",
    )
    parser.add_argument("--namespace", default="palpate", help="the node's namespace")
    parser.add_argument(
        "--out",
        type=Path,
        default=None,
        help="trial logs and recordings under OUT/logs (default: out/ros/<date-time>)",
    )
    parser.add_argument(
        "--network",
        action="store_true",
        help="discoverable beyond this machine (default: DDS on the loopback only)",
    )


def run(args: argparse.Namespace) -> int:
    if not NAMESPACE.fullmatch(args.namespace):
        raise InputError(f"--namespace: {args.namespace!r} is not a ROS 2 namespace")
    if args.config is not None and args.pace is not None:
        raise InputError("--pace: only with --scene (the bench runs in real time)")
    if args.config is None and (args.servo_port or args.board_port):
        raise InputError("--servo-port/--board-port: only with --config (a bench file)")
    try:  # the node's own dependency (the [ros] extra), loaded only here
        from palpate.ros.node import PalpateNode
        from palpate.ros.runner import BenchRunner, SimRunner
    except ImportError as exc:
        raise InputError(
            f"palpate ros needs ROS 2's Python client ({exc}): python3 -m pip install -e "
            "'.[ros]' (the ROS 2 wheels: Python 3.11 on Linux), or source a ROS 2 install"
        ) from None
    out = args.out or Path("out/ros") / datetime.now().strftime("%Y%m%d-%H%M%S")
    runner: SimRunner | BenchRunner
    if args.config is not None:
        ports = {"servo_port": args.servo_port, "board_port": args.board_port}
        runner = BenchRunner(args.config, out=out, **ports)
    else:
        runner = SimRunner(resolve(args.scene or "scenes/robot.yaml"), seed=args.seed, out=out)
    with terminate_as_interrupt(), runner:  # the bench's ports open here (torque off on exit)
        node = PalpateNode(
            runner,
            namespace=args.namespace,
            rate=args.rate,
            network=args.network,
            pace=args.pace,
        )
        try:  # the signals are ours before the announcement: a client may stop it next
            _announce(node.name, runner, out, args)
            node.spin()
        except (KeyboardInterrupt, Terminated) as exc:
            log.warning("palpate ros: stopped (%s)", type(exc).__name__)
        finally:
            node.close()
    return 0


def _announce(name: str, runner: Runner, out: Path, args: argparse.Namespace) -> None:
    from palpate.ros.names import SERVICES, SIMULATION_ONLY, SUBSCRIPTIONS, TOPICS

    namespace = "/" + args.namespace.strip("/")
    served = [t for t in TOPICS if runner.simulated or t not in SIMULATION_ONLY]
    topics = [t if t.startswith("/") else f"{namespace}/{t}" for t in served]
    services = [f"{namespace}/{s}" for s in SERVICES]
    listens = [f"{namespace}/{s}" for s in SUBSCRIPTIONS]
    if args.json:
        facts = {
            "node": name,
            "topics": topics,
            "services": services,
            "subscriptions": listens,
            "out": str(out),
        }
        print(json.dumps(facts), flush=True)
        return
    print(f"ROS 2 node {name} ({runner.label}); logs under {out}")
    print("services: " + ", ".join(services))
    print("topics: " + ", ".join(topics))
    print("teleop: " + ", ".join(listens), flush=True)
    where = "this machine and beyond" if args.network else "this machine only (--network opens it)"
    log.info("DDS: %s; Ctrl-C to stop", where)
