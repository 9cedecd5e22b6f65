"""Which of an airway's wall a robot file's tubes and sensor reach square on (issue 58).

A grid of wall points (insertion x turn round the wall) of a straight airway of ``--airway-mm``
across, each placed through a positioning stage (``robot.positioner.place``): how many are
reached within 2 degrees of the normal, how many only obliquely, and why the rest are refused.
``--add-tube`` adds a tube as the paper's are printed (tip angle, straight and arc length, mm),
for a tip angle that suits a lumen::

    python bench/airway_reach.py --config config/robot-lung-lumen-2.8.yaml --airway-mm 12 \\
        --exposed-mm 2 --add-tube lumen90:90:10:3.93

Geometry only: no trial runs. One line of JSON per tube set.
"""

from __future__ import annotations

import argparse
import collections
import json
import math
import sys

import numpy as np

from palpate.config import load_stack
from palpate.config.schema import TubeConfig
from palpate.maps.surfaces import Lumen
from palpate.robot.positioner import MAX_RESIDUAL, PLACE_REASONS, Approach, Positioner, place

MM = 1e-3


def tube_arg(text: str) -> TubeConfig:
    """NAME:TIP_ANGLE_DEG:STRAIGHT_MM:ARC_MM."""
    name, angle, straight, arc = text.split(":")
    return TubeConfig(
        name=name,
        tip_angle_deg=float(angle),
        straight_length_mm=float(straight),
        arc_length_mm=float(arc),
        flush_translation_mm=0.0,
        compliance_mm_per_n=0.0,
    )


def reach(
    tubes: list[TubeConfig],
    args: argparse.Namespace,
    tip_radius: float,
    limits: tuple[float, float],
) -> dict[str, object]:
    radius = 0.5 * args.airway_mm * MM
    airway = Lumen(origin=(0.0, 0.0, 0.0), axis=(1.0, 0.0, 0.0), radius=radius)
    lateral = (-args.lateral_mm * MM, args.lateral_mm * MM)
    stage = Positioner(x=(-0.2, 0.2), y=lateral, z=lateral)
    how = Approach(
        tip_radius=tip_radius,
        exposed_length=args.exposed_mm * MM,
        standoff=args.standoff_mm * MM,
        translation_limits=limits,
        surface=airway,
        body_radius=args.body_mm * MM,
    )
    counts: collections.Counter[str] = collections.Counter()
    residuals = []
    for u in np.linspace(20 * MM, 60 * MM, args.rings):
        for turn in np.linspace(0.0, 2.0 * math.pi, args.around, endpoint=False):
            p = place(tubes, airway.at(float(u), float(turn) * radius), stage, how)
            counts[PLACE_REASONS[p.status]] += 1
            if p.status in (0, 1):
                residuals.append(math.degrees(p.residual))
    total = args.rings * args.around
    refused = set(PLACE_REASONS.values()) - {PLACE_REASONS[0], PLACE_REASONS[1]}
    return {
        "tubes": [t.name for t in tubes],
        "points": total,
        "square_on": counts[PLACE_REASONS[0]] / total,
        "oblique": counts[PLACE_REASONS[1]] / total,
        "refused": {k: v for k, v in counts.items() if k in refused},
        "residual_deg_median": float(np.median(residuals)) if residuals else None,
        "tolerance_deg": math.degrees(MAX_RESIDUAL),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--config", default="robot.yaml", help="the robot file (its tubes, sensor)")
    parser.add_argument("--airway-mm", type=float, default=12.0, help="the airway's diameter")
    parser.add_argument("--exposed-mm", type=float, default=None, help="exposed length at contact")
    parser.add_argument("--standoff-mm", type=float, default=0.5)
    parser.add_argument("--lateral-mm", type=float, default=4.0, help="lateral travel, +-")
    parser.add_argument("--body-mm", type=float, default=0.5, help="the tube's and sensor's radius")
    parser.add_argument("--add-tube", type=tube_arg, action="append", default=[])
    parser.add_argument("--rings", type=int, default=5)
    parser.add_argument("--around", type=int, default=24)
    args = parser.parse_args(argv)
    stack = load_stack(args.config)
    if args.exposed_mm is None:
        args.exposed_mm = stack.sensor.exposed_length_mm
    limits = (stack.drive.translation_min_mm * MM, stack.drive.translation_max_mm * MM)
    tip = stack.sensor.tip_radius
    sets = [list(stack.tubes)] + ([list(stack.tubes) + args.add_tube] if args.add_tube else [])
    for tubes in sets:
        print(json.dumps(reach(tubes, args, tip, limits)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
