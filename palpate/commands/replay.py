"""Re-run the estimation on a recorded trial log and compare with what the trial reported.

Exit 0 when both estimates are reproduced exactly; 1 when they differ or the log is truncated (a
trial killed while it ran: its records are kept, there is no estimate to reproduce); 2 when the
file is not a trial log or has lines that do not follow the format (each named with its line
number and the field that is wrong)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from palpate.replaylog import replay
from robot.trial.log import TrialLogError


def register(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("log", type=Path, help="a trial log (.jsonl) written by palpate sim/trial")


def run(args: argparse.Namespace) -> int:
    try:
        report = replay(args.log)
    except TrialLogError as exc:
        raise ValueError(str(exc)) from None
    if args.json:
        print(json.dumps(report, indent=2))
        if report.get("damaged"):
            return 2
    else:
        print(f"trial {report['trial']} ({report['log']})")
        if report.get("damaged"):  # bad input: lines that do not follow the log format
            raise ValueError(f"{args.log}: {report['message']}")
        if "message" in report:
            print(report["message"])
            return 1
        m, r = report["modulus"], report["recorded_modulus"]
        print(f"final state: {report['state']} ({report['reason']})")
        print(f"replayed estimate: {'-' if m is None else f'{m / 1e3:.3f} kPa'}")
        print(f"recorded estimate: {'-' if r is None else f'{r / 1e3:.3f} kPa'}")
        j = report.get("joint")
        if j is not None:
            jm = j.get("modulus")
            shown = "-" if jm is None else f"{jm / 1e3:.3f} kPa"
            print(f"replayed joint fit: {shown} ({j['message']})")
        print("identical" if report["identical"] else "DIFFERENT")
    return 0 if report.get("identical") else 1
