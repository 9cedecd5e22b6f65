"""Fit the glued fiber's strain coefficient k'_eps from a recorded (strain, shift) file.

The file is CSV with columns ``strain_ue`` and ``shift_pm`` (see ``sensor/calibration.py``); the
result is the slope with its confidence interval and R^2, as the paper's Fig. 1d.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from sensor.calibration import fit_strain_coefficient, load_pairs_csv


def register(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", type=Path, help="CSV with strain_ue and shift_pm columns")
    parser.add_argument(
        "--confidence", type=float, default=0.95, help="confidence level of the interval"
    )
    parser.add_argument(
        "--through-origin", action="store_true", help="fit shift = k * strain without intercept"
    )


def run(args: argparse.Namespace) -> int:
    strain, shift = load_pairs_csv(args.file)
    try:
        fit = fit_strain_coefficient(
            strain, shift, confidence=args.confidence, through_origin=args.through_origin
        )
    except ValueError as exc:
        raise ValueError(f"{args.file}: {exc}") from None
    if getattr(args, "json", False):
        print(json.dumps({"file": str(args.file), **fit.as_dict()}, indent=2))
        return 0
    lo, hi = fit.ci_pm_per_ue
    pct = round(100 * fit.confidence)
    print(f"calibration of {args.file} ({fit.n} points)")
    print(f"  k'_eps     = {fit.k_pm_per_ue:.4f} pm/ue  ({pct}% CI {lo:.4f} .. {hi:.4f})")
    if not fit.through_origin:
        print(f"  intercept  = {fit.intercept * 1e12:.3f} pm")
    print(f"  R^2        = {fit.r_squared:.5f}")
    print(f"  residual   = {fit.residual_std * 1e12:.3f} pm (std)")
    print(f"  config: fbg.strain_coefficient_pm_per_ue: {fit.k_pm_per_ue:.4f}")
    return 0
