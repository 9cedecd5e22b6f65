"""Where would `active-all` have stopped under another rule? A study's surveys replayed.

The plan's choices do not depend on its stopping rule (the rule only cuts the list), so each
prefix of a survey that ran to its budget is the survey a stricter or looser rule would have
run. For each prefix this maps the probes as the survey does (``campaigns.surveyloop.map_of``),
measures each level's uncertain band (0.05 < P < 0.95) against its boundary's length, and
scores the map against the truth; then, for a family of rules, prints where each survey would
have stopped and what it would have reported there::

    palpate map --scene config/scenes/maps/several.yaml --worlds 24 --whole \\
        --plans active-all:40 --seed 4 --workers 2 --json > study.json
    python bench/map_stop_replay.py study.json

A rule: the main level's boundary known to ``a`` (band <= a x its length; with no region, a
band under ``A``), and two detection levels ``X`` above and below the background each known
when its band is under ``A`` mm^2 (no region) or ``a`` x its length (a region). Only the map's
arithmetic runs (about a minute for 24 surveys), no trial.
"""

from __future__ import annotations

import itertools
import math
import statistics
import sys
from typing import Any

import numpy as np
from map_worlds import read_study, truths  # type: ignore[import-not-found]
from numpy.typing import NDArray

from palpate.campaigns.surveyloop import LENGTH_SCALE_TIPS, inclusion_scores, map_of
from palpate.maps import Patch, Probe
from palpate.maps.gp import MapError, StiffnessMap
from palpate.maps.region import GRID, log_threshold
from palpate.maps.sampling import level_band

MM = 1e-3
FloatArray = NDArray[np.float64]
Level = tuple[float, float]
RISES = (0.1, 0.2, 0.3)


def band(patch: Patch, mean: FloatArray, sd: FloatArray, t: float, sign: float) -> Level:
    """(uncertain area mm^2, boundary length mm) of the level ``t`` (``level_band``)."""
    area, length = level_band(patch, mean, sd, t, sign)
    return area / MM**2, length / MM


def replay(row: dict[str, Any], seed: int, patch: Patch, scale: float) -> list[dict[str, Any]]:
    probes = [Probe.from_record(p) for p in row["probe_list"]]
    known = truths(row)
    out = []
    for n in range(9, len(probes) + 1):
        try:
            m = StiffnessMap.fit(probes[:n], seed=seed, length_scale_max=scale)
        except MapError:
            continue
        mean, sd = m.predict(patch.points(GRID))
        levels = [band(patch, mean, sd, log_threshold(m, mean, None), 1.0)]
        low = m.background + 0.5 * (float(np.min(mean)) - m.background)
        for x in RISES:
            levels.append(band(patch, mean, sd, m.background + math.log1p(x), 1.0))
            levels.append(band(patch, mean, sd, min(low, m.background + math.log(1 - x)), -1.0))
        summary, _ = map_of(probes[:n], patch, None, seed, scale)
        scores = None if summary is None else inclusion_scores(summary.inclusions, known)
        out.append({"n": n, "true": len(known), "levels": levels, "scores": scores})
    return out


def known(level: Level, a: float, area: float) -> bool:
    band_mm2, length = level
    return band_mm2 <= a * length if length > 0 else band_mm2 <= area


def judge(surveys: list[list[dict[str, Any]]], a: float, k: int, area: float) -> str:
    stops, with_one, found, true, false, errors, held = [], [], 0, 0, 0, [], 0
    for rows in surveys:
        stop = next(
            (
                r
                for r in rows
                if known(r["levels"][0], a, area)
                and all(known(lv, a, area) for lv in r["levels"][1 + 2 * k : 3 + 2 * k])
            ),
            rows[-1],
        )
        stops.append(stop["n"])
        if stop["true"]:
            with_one.append(stop["n"])
        s = stop["scores"]
        true, found = true + s["inclusions_true"], found + s["inclusions_found"]
        false += s["false_inclusions"] > 0
        for p in s["per_inclusion"]:
            if p["found"]:
                errors.append(p["center_error_mm"])
                held += p["center_in_ci"]
    return (
        f"a {a} mm, levels +-{RISES[k]:.0%}, nothing-there {area} mm2: stop median "
        f"{statistics.median(stops)} (worlds with inclusions {statistics.median(with_one)}); "
        f"found {found}/{true}; worlds with a false one {false}; centre error median "
        f"{statistics.median(errors):.2f} mm; in CI {held}/{found}"
    )


def main(argv: list[str] | None = None) -> int:
    study, patch, args = read_study(__doc__, argv)
    scale = LENGTH_SCALE_TIPS * args.tip_mm * MM
    surveys = [
        replay(row, study["seed"] * 1000 + row["world"], patch, scale) for row in study["rows"]
    ]
    for a, k, area in itertools.product((0.5, 1.0, 1.5), range(len(RISES)), (3.0, 12.6)):
        print(judge(surveys, a, k, area))
    return 0


if __name__ == "__main__":
    sys.exit(main())
