"""Convert trial logs to MCAP recordings that ROS 2 tools and Foxglove open.

Each ``LOG`` (a ``.jsonl`` trial log of ``palpate sim`` or ``palpate trial``) becomes a
recording of the same name with ``.mcap`` for ``.jsonl`` (``S1.jsonl`` -> ``S1.mcap``) beside
it, or in ``--out``: the messages its trial would have recorded (``robot.records.recording``;
docs/recordings.md). Exit 0 when every log converted, 2 when one is
not a trial log (named, with what is wrong); the others are still converted."""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

from palpate.config.loader import InputError
from palpate.robot.records.export import export
from palpate.robot.records.log import TrialLogError
from palpate.robot.records.recording import read_recording
from palpate.robot.trial.tipforce import axial_loads

log = logging.getLogger(__name__)


def register(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("logs", type=Path, nargs="+", metavar="LOG", help="trial logs (.jsonl)")
    parser.add_argument(
        "--out", type=Path, help="write the recordings into this folder (default: beside each log)"
    )


def run(args: argparse.Namespace) -> int:
    failed: list[str] = []
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
    for path in args.logs:
        target = None if args.out is None else args.out / path.with_suffix(".mcap").name
        try:
            written = export(path, target, axial_loads)
        except (TrialLogError, OSError) as exc:
            failed.append(str(exc) if str(path) in str(exc) else f"{path}: {exc}")
            continue
        rec = read_recording(written)
        counts = ", ".join(f"{topic} {rec.count(topic)}" for topic in sorted(rec.messages))
        print(f"{written}: {counts}")
    if failed:
        raise InputError("not converted: " + "; ".join(failed))
    return 0
