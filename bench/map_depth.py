"""A study on worlds drawn whole (issue 57), its maps read again for depth: each true inclusion
the final map found, against the sphere the map reads under it (``maps.depth``): the centre's
depth, the top's, the sphere's radius (beside the map's footprint radius) and the contrast,
each with its error and whether its 95 % interval holds the truth.

    palpate map --scene config/scenes/maps/several.yaml --worlds 20 --whole \\
        --plans active-all:40 --seed 1 --workers 2 --json > study.json
    python bench/map_depth.py study.json

Only the map's arithmetic runs here (the survey's final probes mapped again as the survey maps
them, ``campaigns.surveyloop.map_of``), no trial; the study's own numbers predate the change
if it was run before it.
"""

from __future__ import annotations

import json
import statistics
import sys
from typing import Any

from map_worlds import read_study, truths

from palpate.campaigns.surveyloop import LENGTH_SCALE_TIPS, map_of, matches
from palpate.maps import Probe

MM = 1e-3


def scores(t: Any, f: Any) -> dict[str, Any]:
    """One inclusion's sphere against its truth (mm; coverage of each interval)."""
    d = f.depth
    true = {"depth": t.depth, "top": t.depth - t.radius, "radius": t.radius}
    read = {
        "depth": (d.depth, d.depth_ci),
        "top": (d.top, d.top_ci),
        "radius": (d.radius, d.radius_ci),
    }
    out: dict[str, Any] = {"kind": t.kind, "contrast_true": t.contrast, "open": list(d.open)}
    for key, (value, (lo, hi)) in read.items():
        out[f"{key}_mm"] = value / MM
        out[f"{key}_error_mm"] = (value - true[key]) / MM
        out[f"{key}_in_ci"] = lo <= true[key] <= hi
        out[f"{key}_width_mm"] = (hi - lo) / MM
    out["footprint_radius_error_mm"] = (f.radius - t.radius) / MM
    lo, hi = d.contrast_ci
    out["contrast"] = d.contrast
    out["contrast_in_ci"] = lo <= t.contrast <= hi
    return out


def main(argv: list[str] | None = None) -> int:
    study, patch, args = read_study(__doc__, argv)
    scale = LENGTH_SCALE_TIPS * args.tip_mm * MM
    rows, unread = [], 0
    for row in study["rows"]:
        if not row["truth"]:
            continue
        seed = study["seed"] * 1000 + row["world"]  # the survey's (campaigns.mapstudy)
        probes = [Probe.from_record(p) for p in row["probe_list"]]
        summary, _ = map_of(probes, patch, None, seed, scale)
        if summary is None:
            continue
        for t, f in matches(summary.inclusions, truths(row))[0]:
            if f is None:
                continue
            if f.depth is None:
                unread += 1
                continue
            rows.append({"world": row["world"], **scores(t, f)})
            print(json.dumps(rows[-1]))
    total: dict[str, Any] = {"read": len(rows), "found_but_unread": unread}
    for key in ("depth", "top", "radius"):
        total[f"{key}_abs_error_mm_median"] = statistics.median(
            abs(r[f"{key}_error_mm"]) for r in rows
        )
        total[f"{key}_error_mm_median"] = statistics.median(r[f"{key}_error_mm"] for r in rows)
        total[f"{key}_in_ci"] = sum(r[f"{key}_in_ci"] for r in rows)
        total[f"{key}_width_mm_median"] = statistics.median(r[f"{key}_width_mm"] for r in rows)
    total["footprint_radius_abs_error_mm_median"] = statistics.median(
        abs(r["footprint_radius_error_mm"]) for r in rows
    )
    total["contrast_in_ci"] = sum(r["contrast_in_ci"] for r in rows)
    total["depth_open"] = sum("depth" in r["open"] for r in rows)
    print(json.dumps({"summary": total}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
