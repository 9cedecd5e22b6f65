"""Re-run the estimation on a recorded trial log and compare with what the trial reported.

Exit 0 when both estimates are reproduced exactly; 1 when they differ or the log is truncated (a
trial killed while it ran: its records are kept, there is no estimate to reproduce); 2 when the
file is not a trial log or has lines that do not follow the format (each named with its line
number and the field that is wrong)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from palpate.config.loader import InputError
from palpate.reports.replay import replay
from palpate.robot.records.log import TrialLogError


def register(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("log", type=Path, help="a trial log (.jsonl) written by palpate sim/trial")
    parser.add_argument(
        "--plot",
        type=Path,
        metavar="PNG",
        help="draw the record's force against indentation with the fit (palpate/reports/fitplot)",
    )


def run(args: argparse.Namespace) -> int:
    try:
        report = replay(args.log)
    except TrialLogError as exc:
        raise InputError(str(exc)) from None
    if args.plot is not None and not report.get("damaged"):
        from palpate.reports.fitplot import record_fit
        from palpate.robot.records.log import read_log

        try:
            report["plot"] = str(record_fit(read_log(args.log), args.plot))
        except ValueError as exc:  # a truncated log has no fit to draw: said, not an error
            report["plot"] = None
            report["plot_message"] = str(exc)
    if args.json:
        print(json.dumps(report, indent=2))
        if report.get("damaged"):
            return 2
    else:
        print(f"trial {report['trial']} ({report['log']})")
        if args.plot is not None:
            print(f"plot: {report.get('plot') or report.get('plot_message')}")
        if report.get("damaged"):  # bad input: lines that do not follow the log format
            raise InputError(f"{args.log}: {report['message']}")
        if "message" in report:
            print(report["message"])
            return 1
        print(f"final state: {report['state']} ({report['reason']})")
        _print_joint(report)
        m, r = report["paper_modulus"], report["recorded_paper_modulus"]
        single = "the paper's single point (Eqs. 13-14), no interval"
        print(f"replayed paper estimate: {'-' if m is None else f'{m / 1e3:.3f} kPa'} ({single})")
        print(f"recorded paper estimate: {'-' if r is None else f'{r / 1e3:.3f} kPa'}")
        for key, what in (
            ("truth_kpa", "true modulus (simulation)"),
            ("reference_kpa", "reference"),
        ):
            if report.get(key) is not None:
                print(f"{what}: {report[key]:.3f} kPa")
        print("identical" if report["identical"] else "DIFFERENT")
    return 0 if report.get("identical") else 1


def _num(x: object) -> float | None:
    return float(x) if isinstance(x, int | float) else None


def _fit_text(j: object) -> str:
    """``148.914 kPa [141.2, 157.3] (95 %)`` or the fit's message."""
    if not isinstance(j, dict):
        return "-"
    E, lo, hi = (_num(j.get(k)) for k in ("modulus", "ci_low", "ci_high"))
    if E is None:
        return f"none ({j.get('message')})"
    text = f"{E / 1e3:.3f} kPa"
    if lo is not None and hi is not None:
        level = _num(j.get("confidence")) or 0.95
        text += f" [{lo / 1e3:.1f}, {hi / 1e3:.1f}] ({round(100 * level)} %)"
    return text


def _verdict_text(v: object) -> str:
    if not isinstance(v, dict):
        return "-"
    reasons = v.get("reasons") or []
    return str(v.get("status")) + ("".join(f"\n    - {r}" for r in reasons) if reasons else "")


def _print_joint(report: dict[str, object]) -> None:
    """The joint fit, its verdict and the calibration as replayed and as recorded."""
    cal = report.get("replayed_calibration")
    if isinstance(cal, dict):
        c, lo, hi = (_num(cal.get(k)) for k in ("compliance", "ci_low", "ci_high"))
        if c is not None and lo is not None and hi is not None:
            print(f"replayed compliance: {c * 1e3:.4g} mm/N [{lo * 1e3:.4g}, {hi * 1e3:.4g}]")
        else:
            print(f"replayed compliance: none ({cal.get('message')})")
    if report.get("joint") is not None:
        print(f"replayed joint fit estimate: {_fit_text(report['joint'])}")
        print(f"recorded joint fit estimate: {_fit_text(report.get('recorded_joint'))}")
    if "replayed_verdict" in report:
        print(f"replayed verdict: {_verdict_text(report['replayed_verdict'])}")
        print(f"recorded verdict: {_verdict_text(report.get('recorded_verdict'))}")
    if "note" in report:
        print(f"note: {report['note']}")
