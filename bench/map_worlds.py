"""A study on worlds drawn whole (issue 57), read again probe by probe: for each world, after
how many probes the map first reads each true inclusion (of its kind, its centre within its
radius, at least 2 mm), and after how many it read all of them; beside the study's own rates.

    palpate map --scene config/scenes/maps/several.yaml --worlds 20 --whole \\
        --plans active-all:40 --seed 1 --workers 2 --json > study.json
    python bench/map_worlds.py study.json

Only the map's arithmetic runs here (each prefix of a survey's probes mapped again as the
survey maps them, ``campaigns.surveyloop.map_of``), no trial.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
from typing import Any

from palpate.campaigns.surveyloop import LENGTH_SCALE_TIPS, Truth, inclusion_scores, map_of
from palpate.maps import Patch, Probe
from palpate.maps.gp import MIN_PROBES

MM = 1e-3


def truths(row: dict[str, Any]) -> list[Truth]:
    return [
        Truth(
            (t["center_mm"][0] * MM, t["center_mm"][1] * MM),
            t["radius_mm"] * MM,
            t["depth_mm"] * MM,
            t["contrast"],
        )
        for t in row["truth"] or []
    ]


def firsts(
    row: dict[str, Any], patch: Patch, seed: int, scale: float
) -> tuple[list[int | None], int | None]:
    """Per true inclusion, the first probe count whose map (the survey's own: ``map_of`` with
    its seed and length scale) reads it; the count that reads all."""
    probes = [Probe.from_record(p) for p in row["probe_list"]]
    known = truths(row)
    first: list[int | None] = [None] * len(known)
    for k in range(MIN_PROBES, len(probes) + 1):
        summary, _ = map_of(probes[:k], patch, None, seed, scale)
        if summary is None:
            continue
        rows = inclusion_scores(summary.inclusions, known)["per_inclusion"]
        for i, r in enumerate(rows):
            if r["found"] and first[i] is None:
                first[i] = k
    every = None if None in first or not first else max(f for f in first if f is not None)
    return first, every


def read_study(
    doc: str | None, argv: list[str] | None
) -> tuple[dict[str, Any], Patch, argparse.Namespace]:
    """A study script's arguments (the study's JSON, its patch and the sensor's tip radius),
    the study read and its patch."""
    parser = argparse.ArgumentParser(description=(doc or "").splitlines()[0])
    parser.add_argument("study", help="the JSON `palpate map --worlds N --whole --json` printed")
    parser.add_argument("--patch-mm", type=float, nargs=4, default=(-10, -10, 10, 10))
    parser.add_argument("--tip-mm", type=float, default=3.5, help="the sensor's tip radius")
    args = parser.parse_args(argv)
    with open(args.study, encoding="utf-8") as fh:
        study = json.load(fh)
    return study, Patch.from_mm(tuple(args.patch_mm)), args


def main(argv: list[str] | None = None) -> int:
    study, patch, args = read_study(__doc__, argv)
    single, every, used = [], [], []
    for row in study["rows"]:
        seed = study["seed"] * 1000 + row["world"]  # the survey's (campaigns.mapstudy)
        first, all_of = firsts(row, patch, seed, LENGTH_SCALE_TIPS * args.tip_mm * MM)
        n = len(row["truth"] or [])
        print(
            json.dumps(
                {
                    "world": row["world"],
                    "true": n,
                    "found": row.get("inclusions_found"),
                    "false": row.get("false_inclusions"),
                    "first_probe": first,
                    "all_by": all_of,
                    "probes": row["probes"],
                }
            )
        )
        used.append(row["probes"])
        if n == 1 and first[0] is not None:
            single.append(first[0])
        if n and all_of is not None:
            every.append(all_of)
    print(json.dumps({"summary": study["summary"]}))
    print(
        json.dumps(
            {
                "median_probes_to_find_a_single_inclusion": statistics.median(single)
                if single
                else None,
                "median_probes_to_find_every_inclusion": statistics.median(every)
                if every
                else None,
                "median_probes_used": statistics.median(used),
            }
        )
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
