"""Calibrate what the paper could not: k'_eps, and the tube's or stage's compliance.

One command, by what it is given:

- a CSV with ``strain_ue`` and ``shift_pm`` columns: k'_eps from paired known strains and
  measured shifts (``sensor/calibration.py``), as the paper's Fig. 1d;
- a CSV with ``force_mn`` and ``shift_pm`` columns, or a frame stream with ``--tip``: the tip
  force grating's sensitivity against a force scale (``sensor/tipcal.py``);
- a frame stream with ``--thermal``, the sensor free through a temperature change (the
  insertion into the body, a bath): each grating's thermal shift per the reference grating's,
  and the residual the configured and the fitted ratios leave (``sensor/thermalcal.py``);
- a recorded stream of raw board frames (any other file, e.g. ``cat /dev/ttyACM0 > frames.bin``
  while the sensor buckles on a rigid reference on the bench-top stage): k'_eps against the
  elastica's strains (``sensor/framecal.py``; ``--exposed-length-mm``, ``--config``);
- trial logs (``.jsonl``) of trials on a rigid reference (a scene's ``rigid: true`` sample, a
  bench trial with ``rigid: true``): the compliance between the stage encoder and the sensor's
  clamp, per tube (the stage on the bench-top), with the robot configuration lines to store it
  (``estimation/fits/compliance.py``; the estimate subtracts it and an uncalibrated one is
  profiled over its plausible range).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from palpate.argtypes import float_in, positive_float, positive_int
from palpate.calibration import calibrate, config_lines
from palpate.config import load_stack
from palpate.config.loader import InputError
from palpate.config.schema import MM, StackConfig
from palpate.estimation.beam.stage import rig_key
from palpate.estimation.fits.compliance import ComplianceFit
from palpate.reports.replay import replay
from palpate.robot.records.log import read_log
from palpate.sensor.calibration import (
    CalibrationFit,
    csv_columns,
    fit_strain_coefficient,
    load_pairs_csv,
)
from palpate.sensor.framecal import calibrate_frames, read_frames
from palpate.sensor.thermalcal import ThermalFit, fit_thermal_frames
from palpate.sensor.tipcal import fit_tip_csv, fit_tip_frames, is_tip_csv


def register(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "file",
        type=Path,
        nargs="+",
        help="a CSV (strain_ue, shift_pm), a raw frame stream, or rigid-reference trial logs",
    )
    parser.add_argument(
        "--confidence",
        type=float_in(0.0, 1.0, low_open=True, high_open=True),
        default=0.95,
        help="confidence level of the interval",
    )
    parser.add_argument(
        "--through-origin", action="store_true", help="CSV: fit shift = k * strain, no intercept"
    )
    parser.add_argument(
        "--config", default="robot.yaml", help="frames: the robot configuration (sensor, board)"
    )
    parser.add_argument(
        "--exposed-length-mm",
        type=positive_float,
        help="frames: the sensor's exposed length (default: sensor.exposed_length_mm)",
    )
    parser.add_argument(
        "--rest-frames",
        type=positive_int,
        default=20,
        help="frames: the first N are at rest (zero)",
    )
    parser.add_argument(
        "--tip",
        action="store_true",
        help="frames: calibrate the tip force grating against the board's force scale reading",
    )
    parser.add_argument(
        "--thermal",
        action="store_true",
        help="frames: each grating's thermal ratio to the reference grating (a free sensor "
        "through a temperature change)",
    )


def run(args: argparse.Namespace) -> int:
    files: list[Path] = args.file
    if all(f.suffix == ".jsonl" for f in files):
        return _compliance(files, args)
    if len(files) != 1:
        raise InputError("give one CSV or one frame stream, or trial logs (.jsonl) only")
    path = files[0]
    if args.thermal:
        return _thermal(path, args)
    if args.tip or is_tip_csv(path, csv_columns(path)):
        return _tip(path, args)
    if path.suffix.lower() == ".csv":
        strain, shift = load_pairs_csv(path)
        try:
            fit = fit_strain_coefficient(
                strain, shift, confidence=args.confidence, through_origin=args.through_origin
            )
        except ValueError as exc:
            raise InputError(f"{path}: {exc}") from None
    else:
        stack = load_stack(args.config)
        length = (args.exposed_length_mm or stack.sensor.exposed_length_mm) * MM
        fit = calibrate_frames(
            read_frames(path, stack),
            stack,
            length,
            rest_frames=args.rest_frames,
            confidence=args.confidence,
        )
    _print_fit(path, fit, args)
    return 0


def _print_fit(path: Path, fit: CalibrationFit, args: argparse.Namespace) -> None:
    if getattr(args, "json", False):
        print(json.dumps({"file": str(path), **fit.as_dict()}, indent=2))
        return
    lo, hi = fit.ci_pm_per_ue
    pct = round(100 * fit.confidence)
    print(f"calibration of {path} ({fit.n} points)")
    print(f"  k'_eps     = {fit.k_pm_per_ue:.4f} pm/ue  ({pct}% CI {lo:.4f} .. {hi:.4f})")
    if not fit.through_origin:
        print(f"  intercept  = {fit.intercept * 1e12:.3f} pm")
    print(f"  R^2        = {fit.r_squared:.5f}")
    print(f"  residual   = {fit.residual_std * 1e12:.3f} pm (std)")
    print(f"  config: fbg.strain_coefficient_pm_per_ue: {fit.k_pm_per_ue:.4f}")


def _tip(path: Path, args: argparse.Namespace) -> int:
    """The tip grating's sensitivity from a force_mn/shift_pm CSV or a frame stream."""
    if path.suffix.lower() == ".csv":
        fit = fit_tip_csv(path, confidence=args.confidence)
    else:
        stack = load_stack(args.config)
        block = read_frames(path, stack)
        fit = fit_tip_frames(block, stack, rest_frames=args.rest_frames, confidence=args.confidence)
    if getattr(args, "json", False):
        print(json.dumps({"file": str(path), **fit.as_dict()}, indent=2))
        return 0
    lo, hi = fit.ci_pm_per_mn
    pct = round(100 * fit.line.confidence)
    print(f"tip grating calibration of {path} ({fit.line.n} points)")
    print(
        f"  sensitivity = {fit.sensitivity_pm_per_mn:.4f} pm/mN  ({pct}% CI {lo:.4f} .. {hi:.4f})"
    )
    print(f"  R^2         = {fit.line.r_squared:.5f}")
    print(f"  residual    = {fit.line.residual_std * 1e12:.3f} pm (std)")
    print(f"  config: {fit.config_line()}")
    return 0


def _thermal(path: Path, args: argparse.Namespace) -> int:
    """The gratings' thermal ratios from a free sensor's frame stream."""
    stack = load_stack(args.config)
    try:
        fit = fit_thermal_frames(read_frames(path, stack), stack, confidence=args.confidence)
    except ValueError as exc:
        raise InputError(f"{path}: {exc}") from None
    if getattr(args, "json", False):
        lines = fit.config_lines(stack)
        print(json.dumps({"file": str(path), **fit.as_dict(), "config": lines}, indent=2))
        return 0
    for line in thermal_lines(path, fit, stack):
        print(line)
    return 0


def thermal_lines(path: Path, fit: ThermalFit, stack: StackConfig) -> list[str]:
    """The thermal calibration's table: each grating's ratio, its interval, the residuals."""
    pct = round(100 * fit.lines[0].confidence)
    out = [
        f"thermal calibration of {path} ({fit.frames} frames over {fit.duration:.1f} s; "
        f"the reference grating moved {fit.span * 1e12:.1f} pm)",
        f"  grating  ratio   ({pct}% CI)          residual: configured  calibrated",
    ]
    for label, line, c, rc, rf in zip(
        fit.labels,
        fit.lines,
        fit.configured,
        fit.residual_configured,
        fit.residual_calibrated,
        strict=True,
    ):
        lo, hi = line.ci
        out.append(
            f"  {label:<7}  {line.k_eps:.5f} ({lo:.5f} .. {hi:.5f})  "
            f"{rc * 1e12:8.2f} pm ({c:.4f})  {rf * 1e12:6.2f} pm"
        )
    out += [f"  config: {line}" for line in fit.config_lines(stack)]
    return out


def _compliance(files: list[Path], args: argparse.Namespace) -> int:
    """The compliance per tube (stage) from rigid-reference trial logs, re-fitted from their
    samples (``palpate replay``); exit 1 when none gives one."""
    fits = []
    rows: list[dict[str, object]] = []
    for path in files:
        report = replay(path)
        cal = report.get("replayed_calibration")
        spec = _spec(path)
        if not isinstance(cal, dict) or spec is None:
            rows.append({"log": str(path), "message": "not a rigid-reference trial log"})
            continue
        fit = ComplianceFit(**cal)
        fits.append((rig_key(spec["kind"], spec["tube"]), fit))
        rows.append({"log": str(path), "key": fits[-1][0], **cal})
    found = calibrate(fits)
    if getattr(args, "json", False):
        ranges = {k: [lo / MM, hi / MM] for k, (lo, hi) in found.items()}
        print(json.dumps({"trials": rows, "compliance_mm_per_n": ranges}, indent=2))
    else:
        for r in rows:
            c = r.get("compliance")
            what = (
                r.get("message") if not isinstance(c, float) else f"{c / MM:.4g} mm/N ({r['key']})"
            )
            print(f"{r['log']}: {what}")
        for line in config_lines(found):
            print(f"config: {line}")
    return 0 if found else 1


def _spec(path: Path) -> dict[str, str] | None:
    spec = read_log(path).header.get("spec")
    return spec if isinstance(spec, dict) else None
