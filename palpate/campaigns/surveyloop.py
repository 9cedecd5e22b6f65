"""A map survey's loop, one for the bench and the simulator (issue 40; docs/maps.md): the plan
(``maps.sampling``) picks each next point from the probes so far, a probe (a whole
trial at that point: ``palpate.campaigns.survey`` in simulation, ``palpate.services.benchmap``
on the bench's x-y stage) answers it, the probes are appended to ``probes.jsonl`` as they finish (a
killed survey resumes where it stopped: every plan is a function of the probes before it), and
the map summarises them::

    plan = SurveyPlan.of(campaign_patch_mm, "active", 30, threshold=None, seed=0, scale=4.2e-3)
    result = run_plan(plan, probe_at, run_dir=Path("out/map/run"))
    result.summary.found, result.summary.centre
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
from threadpoolctl import threadpool_limits

from palpate.maps import (
    MapError,
    MapSummary,
    Patch,
    Probe,
    StiffnessMap,
    plan_for,
    summarise,
)
from palpate.maps.gp import LENGTH_SCALE_MAX
from palpate.maps.inclusions import find_inclusions
from palpate.maps.probes import normal_scores
from palpate.maps.region import GRID_FIELDS, PROBE_FIELDS, Inclusion, grid_frame, probe_frame
from palpate.robot.records.ros2 import nanoseconds

if TYPE_CHECKING:
    from palpate.live import View
    from palpate.robot.records.cdr import Transform

MM = 1e-3
PROBES_FILE = "probes.jsonl"
# the map's longest length scale in tip radii: a tip sees an inclusion over about its own radius
# (3.6 mm fitted on a dense raster of the shipped scene under the 3.5 mm tip; docs/maps.md)
LENGTH_SCALE_TIPS = 1.2
Point = tuple[float, float]
# a probe at a point, given the probes before it: the probe and the trial's outcome
ProbeAt = Callable[[list[Probe], Point], tuple[Probe, Any]]


def probe_name(k: int, point: Point) -> str:
    """The k-th probe's trial name, with its point (m) in mm: ``p007-x+3.33-y-3.33``."""
    return f"p{k:03d}-x{point[0] / MM:+.2f}-y{point[1] / MM:+.2f}"


class SurveyStopped(Exception):  # noqa: N818 - an ending, not an error
    """A probe's trial ended the survey (a fault: the robot stopped and retracted): the probe
    as recorded, the trial's outcome, and why."""

    def __init__(self, probe: Probe, outcome: Any, why: str) -> None:
        super().__init__(why)
        self.probe, self.outcome, self.why = probe, outcome, why


@dataclass(frozen=True)
class SurveyPlan:
    """What a map campaign asks: the patch (m), the strategy, the probe budget, the threshold
    (Pa; None: from the data), the seed, and the map's longest length scale (m)."""

    patch: Patch
    strategy: str
    budget: int
    threshold: float | None
    seed: int
    scale: float

    @classmethod
    def of(
        cls,
        patch_mm: tuple[float, ...],
        strategy: str,
        budget: int,
        *,
        threshold: float | None,
        seed: int,
        tip_radius: float,
    ) -> SurveyPlan:
        """From a campaign's keys; the length scale from the tip (``LENGTH_SCALE_TIPS``)."""
        patch = Patch.from_mm((patch_mm[0], patch_mm[1], patch_mm[2], patch_mm[3]))
        return cls(patch, strategy, budget, threshold, seed, LENGTH_SCALE_TIPS * tip_radius)


@dataclass(frozen=True)
class Truth:
    """The simulated inclusion (m, Pa), None for a homogeneous sample."""

    centre: tuple[float, float]
    radius: float
    depth: float
    contrast: float
    others: tuple[Truth, ...] = ()  # the sample's other inclusions

    @property
    def kind(self) -> str:
        return "stiff" if self.contrast > 1.0 else "soft"

    def one(self) -> dict[str, Any]:
        return {
            "center_mm": [self.centre[0] / MM, self.centre[1] / MM],
            "radius_mm": self.radius / MM,
            "depth_mm": self.depth / MM,
            "contrast": self.contrast,
            "kind": self.kind,
        }

    def as_dict(self) -> dict[str, Any]:
        first = self.one()
        return {
            **{f"inclusion_{k}": first[k] for k in ("center_mm", "radius_mm", "depth_mm")},
            "contrast": self.contrast,
            "inclusions": [t.one() for t in (self, *self.others)],
        }


class CarriedRobot(Protocol):
    """Where a robot carried to each probe stood: ``frames(point)`` gives the ``/tf`` transforms
    (``world`` -> ``base``, and ``world`` -> ``sample`` where the tissue's pose is known) of the
    probe at ``point`` (``campaigns.throughrobot.ThroughRobot``, ``robot.xystage.Gantry``)."""

    def frames(self, point: Point) -> list[Transform]: ...


@dataclass
class SurveyResult:
    """A survey's probes, its map's answer (None when too few probes gave a number), why it
    stopped, its lab time (s) and compute time of the map (s), and the truth in simulation."""

    probes: list[Probe]
    summary: MapSummary | None
    stopped: str
    lab_time: float
    map_seconds: float
    truth: Truth | None
    patch: Patch
    outcomes: list[Any] = field(default_factory=list)  # the probes' trials
    length_scale_max: float = LENGTH_SCALE_MAX  # the map's (m)
    reach: CarriedRobot | None = None  # how the probes reached the patch through the robot

    def scores(self) -> dict[str, Any]:
        """Against the truth: the centre's error (mm), and the boundary's sensitivity,
        specificity and error (the area where the two regions disagree, mm^2) on the summary's
        grid (the truth's region: the inclusion's footprint, a disc of its radius about its
        centre); a homogeneous sample's "false alarm"."""
        s = self.summary
        normal = normal_scores(self.probes)
        if self.truth is None:
            return {
                "false_alarm": bool(s is not None and s.found),
                "false_inclusions": 0 if s is None else len(s.inclusions),
                **normal,
            }
        out: dict[str, Any] = {"detected": bool(s is not None and s.found), **normal}
        if s is None:
            return out
        out.update(inclusion_scores(s.inclusions, (self.truth, *self.truth.others)))
        xx, yy = np.meshgrid(s.x, s.y)
        t = self.truth
        inside = np.hypot(xx - t.centre[0], yy - t.centre[1]) <= t.radius
        said = s.inside(xx, yy)
        out["sensitivity"] = float((said & inside).sum() / max(inside.sum(), 1))
        out["specificity"] = float((~said & ~inside).sum() / max((~inside).sum(), 1))
        cell = (s.x[1] - s.x[0]) * (s.y[1] - s.y[0]) / MM**2
        out["boundary_error_mm2"] = float((said ^ inside).sum() * cell)
        if s.centre is not None:
            out["center_error_mm"] = (
                math.hypot(s.centre[0] - t.centre[0], s.centre[1] - t.centre[1]) / MM
            )
        if s.centre_ci is not None and s.radius_ci is not None:
            (x0, x1), (y0, y1) = s.centre_ci
            out["center_in_ci"] = bool(x0 <= t.centre[0] <= x1 and y0 <= t.centre[1] <= y1)
            out["radius_in_ci"] = bool(s.radius_ci[0] <= t.radius <= s.radius_ci[1])
        return out

    def as_dict(self) -> dict[str, Any]:
        summary = {} if self.summary is None else self.summary.as_dict()
        return {
            "probes_used": len(self.probes),
            "probes_with_number": sum(p.usable for p in self.probes),
            "inclusion_found": bool(self.summary is not None and self.summary.found),
            **summary,
            "stopped": self.stopped,
            "lab_time_s": self.lab_time,
            "map_compute_s_per_probe": self.map_seconds / max(len(self.probes), 1),
            "truth": None if self.truth is None else self.truth.as_dict(),
            "scores": self.scores(),
            "probes": [p.as_dict() for p in self.probes],
        }


def matches(
    found: Sequence[Inclusion], truths: Sequence[Truth]
) -> tuple[list[tuple[Truth, Inclusion | None]], list[Inclusion]]:
    """Every true inclusion with the reported one of its kind nearest it whose centre is
    within its radius (at least 2 mm) of its own (None: not found), each reported one taken
    once; and the reported ones no true inclusion took (false)."""
    free = list(found)
    pairs: list[tuple[Truth, Inclusion | None]] = []
    for t in truths:
        reach = max(t.radius, 2 * MM)
        same = [f for f in free if f.kind == t.kind]
        dist = [math.hypot(f.centre[0] - t.centre[0], f.centre[1] - t.centre[1]) for f in same]
        if not same or min(dist) > reach:
            pairs.append((t, None))
            continue
        f = same[int(np.argmin(dist))]
        free.remove(f)
        pairs.append((t, f))
    return pairs, free


def inclusion_scores(found: Sequence[Inclusion], truths: Sequence[Truth]) -> dict[str, Any]:
    """Every true inclusion against the map's list (:func:`matches`). Per true inclusion:
    found, the centre's error (mm), whether the centre's interval holds it, and where the map
    read its sphere the depth's error (of its centre, mm) and whether the depth's interval
    holds it."""
    pairs, false = matches(found, truths)
    rows: list[dict[str, Any]] = []
    for t, f in pairs:
        if f is None:
            rows.append({"kind": t.kind, "found": False})
            continue
        (x0, x1), (y0, y1) = f.centre_ci
        held = x0 <= t.centre[0] <= x1 and y0 <= t.centre[1] <= y1
        error = math.hypot(f.centre[0] - t.centre[0], f.centre[1] - t.centre[1]) / MM
        row = {"kind": t.kind, "found": True, "center_error_mm": error, "center_in_ci": held}
        if f.depth is not None:
            lo, hi = f.depth.depth_ci
            row["depth_error_mm"] = abs(f.depth.depth - t.depth) / MM
            row["depth_in_ci"] = lo <= t.depth <= hi
        rows.append(row)
    return {
        "inclusions_found": sum(r["found"] for r in rows),
        "inclusions_true": len(truths),
        "false_inclusions": len(false),
        "per_inclusion": rows,
    }


def run_plan(
    survey: SurveyPlan,
    probe_at: ProbeAt,
    *,
    run_dir: Path | None = None,
    on_probe: Callable[[Probe], None] | None = None,
    live: View | None = None,
    truth: Truth | None = None,
) -> SurveyResult:
    """Probe until the plan stops; with ``run_dir`` the probes in ``probes.jsonl``, read back
    first (a resumed survey carries on from its last probe); with ``live`` the map after each
    probe on the live view (``/map/grid``, ``/map/probes``). A probe that raises
    :class:`SurveyStopped` (its trial faulted) ends the survey, recorded; the map is what the
    probes say."""
    patch, scale = survey.patch, survey.scale
    plan = plan_for(
        survey.strategy,
        patch,
        survey.budget,
        seed=survey.seed,
        threshold=survey.threshold,
        length_scale_max=scale,
    )
    probes = read_probes(run_dir / PROBES_FILE) if run_dir is not None else []
    outcomes: list[Any] = []
    map_seconds = 0.0
    stopped = ""
    while True:
        t0 = time.process_time()
        with threadpool_limits(1):  # tens of probes: more BLAS threads only wait on each other
            point = plan.next(probes)
        map_seconds += time.process_time() - t0
        if point is None:
            break
        try:
            probe, outcome = probe_at(probes, point)
        except SurveyStopped as stop:
            probe, outcome = stop.probe, stop.outcome
            stopped = f"stopped at probe {len(probes) + 1}: {stop.why}"
        probes.append(probe)
        outcomes.append(outcome)
        if run_dir is not None:
            append_probe(run_dir / PROBES_FILE, probe)
        if on_probe is not None:
            on_probe(probe)
        if live is not None:
            publish_map(live, probes, patch, survey.threshold, scale)
        if stopped:
            break
    stopped = stopped or getattr(plan, "stopped", "") or f"{len(probes)} of {survey.budget} probes"
    t0 = time.process_time()
    with threadpool_limits(1):
        summary, note = map_of(probes, patch, survey.threshold, survey.seed, scale)
    map_seconds += time.process_time() - t0
    lab = sum(p.lab_time for p in probes)
    return SurveyResult(
        probes, summary, stopped + note, lab, map_seconds, truth, patch, outcomes, scale
    )


def map_of(
    probes: list[Probe], patch: Patch, threshold: float | None, seed: int, scale: float
) -> tuple[MapSummary | None, str]:
    """The probes' map summarised over ``patch`` (None and why, when it cannot be made)."""
    try:
        fitted = StiffnessMap.fit(probes, seed=seed, length_scale_max=scale)
    except MapError as exc:
        return None, f"; no map: {exc}"
    summary = summarise(fitted, patch, threshold=threshold, seed=seed)
    every = find_inclusions(fitted, patch, summary, seed=seed)
    return replace(summary, inclusions=tuple(every)), ""


def publish_map(
    live: View, probes: list[Probe], patch: Patch, threshold: float | None, scale: float
) -> None:
    """The probes so far and their map on the live view, stamped with the lab time."""
    stamp = nanoseconds(sum(p.lab_time for p in probes))
    live.cloud("/map/probes", stamp, PROBE_FIELDS, probe_frame(probes))
    grid = grid_frame(probes, patch, threshold=threshold, length_scale_max=scale)
    if grid is not None:
        live.cloud("/map/grid", stamp, GRID_FIELDS, grid)


def read_probes(path: Path) -> list[Probe]:
    """The probes a survey wrote (none if the file is missing); a torn last line is dropped."""
    if not path.exists():
        return []
    out = []
    for line in path.read_text(encoding="utf-8").splitlines():
        try:
            out.append(Probe.from_record(json.loads(line)))
        except ValueError:
            break  # a line cut by a kill: the probe is run again
    return out


def append_probe(path: Path, probe: Probe) -> None:
    with path.open("a", encoding="utf-8") as fh:
        fh.write(json.dumps(probe.record(), separators=(",", ":")) + "\n")
