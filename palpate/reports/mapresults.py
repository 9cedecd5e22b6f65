"""A map's run folder and its lines for a person, one for ``palpate map`` (simulation) and
``palpate trial`` with a bench file's ``map:`` (the x-y stage): ``map.json`` (the probes, the
map's answer, the truth in simulation), ``map.mcap`` (the map as point clouds) and ``map.png``::

    payload = write_map_results(result, run_dir, info, threshold=None, title="S8", plots=True)
    for line in map_lines(result, payload["run_dir"], info["strategy"]): print(line)
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from palpate.campaigns.surveyloop import SurveyResult
from palpate.maps import MapSummary
from palpate.maps.probes import NORMAL_TOLERANCE, normal_scores
from palpate.maps.region import Inclusion


def write_map_results(
    result: SurveyResult,
    run_dir: Path,
    info: dict[str, Any],
    *,
    threshold: float | None,
    title: str,
    plots: bool,
) -> dict[str, Any]:
    """Write the run folder's map files; the payload of ``map.json`` with the recording's and
    the figure's paths (``info``: what the run was asked, first in the payload)."""
    payload = {**info, "run_dir": str(run_dir), **result.as_dict()}
    (run_dir / "map.json").write_text(json.dumps(payload, indent=2) + "\n", encoding="utf-8")
    from palpate.reports.maprecording import write_map_recording

    payload["recording"] = str(write_map_recording(result, run_dir / "map.mcap", threshold))
    if plots:
        from palpate.reports.mapfig import map_figure

        payload["figure"] = str(map_figure(result, run_dir / "map.png", title))
        from palpate.campaigns.throughrobot import ThroughRobot

        if isinstance(result.reach, ThroughRobot):  # the tissue's pose known: the simulator's
            from palpate.reports.map3d import map3d_figure

            path = map3d_figure(result, result.reach, run_dir / "map3d.png", title)
            payload["figure_3d"] = str(path)
    return payload


def map_lines(result: SurveyResult, run_dir: Path, title: str, strategy: str) -> list[str]:
    """The survey's answer as a person reads it: probes and lab time, the evidence, the centre
    with its interval and the radius, the truth and scores in simulation, the run folder."""
    s = result.summary
    lines = [
        f"{title}: {len(result.probes)} probes ({strategy}), "
        f"{result.lab_time:.0f} s of lab time; {result.stopped}"
    ]
    if s is None:
        lines.append("no map: too few probes gave a number")
    else:
        lines.append(s.evidence)
        if s.found and s.centre is not None and s.centre_ci is not None and s.radius is not None:
            (x0, x1), (y0, y1) = s.centre_ci
            lines.append(
                f"centre ({s.centre[0] * 1e3:+.2f}, {s.centre[1] * 1e3:+.2f}) mm "
                f"[x {x0 * 1e3:+.2f}..{x1 * 1e3:+.2f}, y {y0 * 1e3:+.2f}..{y1 * 1e3:+.2f}], "
                f"radius {s.radius * 1e3:.2f} mm{_radius_note(s)}"
            )
        lines += [inclusion_line(k + 1, f) for k, f in enumerate(s.inclusions)]
    normal = normal_scores(result.probes)
    if normal:
        lines.append(
            f"through the robot: every probe's axis within {normal['normal_error_max_deg']:.1f} "
            f"deg of the true surface normal; {normal['probes_off_normal']} beyond "
            f"{math.degrees(NORMAL_TOLERANCE):g} deg, "
            f"{normal['off_normal_unflagged']} of them without a verdict that says so"
        )
    if result.truth is not None:
        t = result.truth
        lines.append(
            f"truth: centre ({t.centre[0] * 1e3:+.2f}, {t.centre[1] * 1e3:+.2f}) mm, "
            f"radius {t.radius * 1e3:.2f} mm, {t.depth * 1e3:.1f} mm deep, {t.contrast:.1f}x; "
            f"scores: {score_text(result.scores())}"
        )
    lines.append(f"run folder: {run_dir}")
    return lines


SCORE_NAMES = {
    "detected": "detected",
    "false_alarm": "false alarm",
    "sensitivity": "sensitivity",
    "specificity": "specificity",
    "boundary_error_mm2": "boundary error (mm^2)",
    "center_error_mm": "centre error (mm)",
    "center_in_ci": "centre in its 95 % box",
    "radius_in_ci": "radius in its 95 % interval",
}


def inclusion_line(number: int, f: Inclusion) -> str:
    """One inclusion of the map as a person reads it: kind, centre, radius and, where the map
    read its sphere, how deep it lies and how stiff, with 95 % intervals (mm).

    >>> box = ((3.8e-3, 4.2e-3), (-4.2e-3, -3.8e-3))
    >>> nodule = Inclusion("stiff", (4e-3, -4e-3), box, 2.6e-3, (2e-3, 3e-3), 9e5, 1.0)
    >>> for part in inclusion_line(1, nodule).split("; "):
    ...     print(part)
    inclusion 1 (stiff): centre (+4.00, -4.00) mm, radius 2.60 mm
    depth not read (too few probes about it)
    """
    text = (
        f"inclusion {number} ({f.kind}): centre ({f.centre[0] * 1e3:+.2f}, "
        f"{f.centre[1] * 1e3:+.2f}) mm, radius {f.radius * 1e3:.2f} mm"
    )
    d = f.depth
    if d is None:
        return text + "; depth not read (too few probes about it)"
    bounded = " (the probes bound it on one side only)" if "depth" in d.open else ""
    return (
        f"{text}; centre {d.depth * 1e3:.1f} mm deep [{d.depth_ci[0] * 1e3:.1f}.."
        f"{d.depth_ci[1] * 1e3:.1f}]{bounded}, top {d.top * 1e3:.1f} mm "
        f"[{d.top_ci[0] * 1e3:.1f}..{d.top_ci[1] * 1e3:.1f}], {d.contrast:.2g}x the tissue "
        f"[{d.contrast_ci[0]:.2g}..{d.contrast_ci[1]:.2g}]"
    )


def score_text(scores: dict[str, object]) -> str:
    """A survey's scores against the truth, named and rounded for a person.

    >>> score_text({"detected": True, "sensitivity": 0.973164, "center_error_mm": 0.0612})
    'detected yes, sensitivity 0.97, centre error (mm) 0.06'
    """
    parts = []
    for key, value in scores.items():
        name = SCORE_NAMES.get(key, key.replace("_", " "))
        if isinstance(value, bool):
            text = "yes" if value else "no"
        elif isinstance(value, float):
            text = f"{value:.2f}"
        else:
            text = str(value)
        parts.append(f"{name} {text}")
    return ", ".join(parts)


def _radius_note(s: MapSummary) -> str:
    """The radius's interval and where it comes from (the extent's disc, or the region)."""
    lo, hi = s.radius_ci if s.radius_ci is not None else (None, None)
    band = "" if lo is None or hi is None else f" [{lo * 1e3:.2f}..{hi * 1e3:.2f}]"
    if s.extent is None or s.apparent_radius is None:
        return f"{band} (the region above the threshold)"
    return (
        f"{band} (the disc through the tip's contact; the region above the threshold: "
        f"{s.apparent_radius * 1e3:.2f} mm)"
    )
