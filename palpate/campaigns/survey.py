"""A map survey in simulation: probe a patch of one sample point by point, map it, find the
inclusion (issue 40; docs/maps.md).

Each probe is a whole trial of the one session (``simulation.trial.run_sim_trial``: the servos
on the emulated bus, the board's frames, the state machine, the estimator), on the bench column
at the campaign's first exposed length, with the sample moved under the tip: the world sees the
sample's inclusion from the probe's point (``sim.sample_law.fe_world``; a map scene interpolates
the 3-D factor between solved distances, ``fidelity.inclusion_offsets: interpolated``). The plan
(``estimation.maps.sampling``) picks each next point from the probes so far; the lab time adds
each trial's simulated time and the x-y stage's travel at ``campaign.stage_speed_mm_per_s``.
Probes are appended to ``probes.jsonl`` as they finish, so a killed survey resumes where it
stopped (every plan is a function of the probes before it)::

    result = run_survey(scene, stack, seed=0, run_dir=Path("out/map/run"))
    result.summary.found, result.summary.centre, result.scores()
"""

from __future__ import annotations

import dataclasses
import json
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from palpate.config.sample import SampleConfig
from palpate.config.scene import SceneConfig
from palpate.config.schema import StackConfig
from palpate.estimation.maps import (
    MapError,
    MapSummary,
    Patch,
    Probe,
    StiffnessMap,
    plan_for,
    summarise,
)
from palpate.estimation.maps.gp import LENGTH_SCALE_MAX
from palpate.estimation.maps.region import GRID_FIELDS, PROBE_FIELDS, grid_frame, probe_frame
from palpate.robot.records.ros2 import nanoseconds
from palpate.simulation.trial import TrialOutcome, run_sim_trial
from palpate.simulation.world import TrialSpec

if TYPE_CHECKING:
    from palpate.live import LiveView

MM = 1e-3
PROBES_FILE = "probes.jsonl"
# the map's longest length scale in tip radii: a tip sees an inclusion over about its own radius
# (3.6 mm fitted on a dense raster of the shipped scene under the 3.5 mm tip; docs/maps.md)
LENGTH_SCALE_TIPS = 1.2


@dataclass(frozen=True)
class Truth:
    """The simulated inclusion (m, Pa), None for a homogeneous sample."""

    centre: tuple[float, float]
    radius: float
    depth: float
    contrast: float

    def as_dict(self) -> dict[str, Any]:
        return {
            "inclusion_center_mm": [self.centre[0] / MM, self.centre[1] / MM],
            "inclusion_radius_mm": self.radius / MM,
            "inclusion_depth_mm": self.depth / MM,
            "contrast": self.contrast,
        }


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
    outcomes: list[TrialOutcome] = field(default_factory=list)
    length_scale_max: float = LENGTH_SCALE_MAX  # the map's (m)

    def scores(self) -> dict[str, Any]:
        """Against the truth: the centre's error (mm), and the boundary's sensitivity,
        specificity and error (the area where the two regions disagree, mm^2) on the summary's
        grid (the truth's region: the inclusion's footprint, a disc of its radius about its
        centre); a homogeneous sample's "false alarm"."""
        s = self.summary
        if self.truth is None:
            return {"false_alarm": bool(s is not None and s.found)}
        out: dict[str, Any] = {"detected": bool(s is not None and s.found)}
        if s is None:
            return out
        xx, yy = np.meshgrid(s.x, s.y)
        t = self.truth
        inside = np.hypot(xx - t.centre[0], yy - t.centre[1]) <= t.radius
        said = s.p_above > 0.5 if s.found else np.zeros_like(inside)
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


def truth_of(sample: SampleConfig) -> Truth | None:
    if not sample.inclusions:
        return None
    inc = sample.inclusions[0]
    c = inc.center
    return Truth((c[0], c[1]), inc.radius, c[2], inc.modulus / sample.modulus)


def moved_scene(
    scene: SceneConfig, sample: SampleConfig, point: tuple[float, float]
) -> SceneConfig:
    """The scene whose one sample sits so that the tip, indenting where a single trial does,
    presses at ``point`` (m) of the patch: the inclusions' centres relative to that point."""
    moved = tuple(
        dataclasses.replace(
            inc,
            center_mm=(
                inc.center_mm[0] - point[0] / MM,
                inc.center_mm[1] - point[1] / MM,
                inc.center_mm[2],
            ),
        )
        for inc in sample.inclusions
    )
    return dataclasses.replace(scene, samples=(dataclasses.replace(sample, inclusions=moved),))


def probe_spec(
    scene: SceneConfig, sample: SampleConfig, k: int, point: tuple[float, float], seed: int
) -> TrialSpec:
    """The k-th probe's trial: the bench column at the campaign's first exposed length."""
    length = scene.campaign.exposed_lengths[0]
    return TrialSpec(
        trial_id=f"p{k:03d}-x{point[0] / MM:+.2f}-y{point[1] / MM:+.2f}",
        kind="bench",
        sample=sample.name,
        modulus=sample.modulus,
        poisson=sample.poisson,
        tube="straight",
        orientation="downward",
        roll=0.0,
        exposed_length=length,
        seed=seed * 1_000_003 + k,
    )


def probe_of(o: TrialOutcome, point: tuple[float, float], travel_time: float) -> Probe:
    jf, v = o.joint, o.verdict
    ok = jf is not None and jf.success and jf.modulus is not None
    ci = None
    if ok and jf is not None and jf.ci_low is not None and jf.ci_high is not None:
        ci = (jf.ci_low, jf.ci_high)
    return Probe(
        point[0],
        point[1],
        jf.modulus if ok and jf is not None else None,
        ci,
        "none" if v is None else v.status,
        () if v is None else tuple(v.reasons) or (() if ok else (o.reason,)),
        o.sim_time + travel_time,
    )


def run_survey(
    scene: SceneConfig,
    stack: StackConfig,
    *,
    seed: int = 0,
    strategy: str | None = None,
    max_probes: int | None = None,
    run_dir: Path | None = None,
    on_probe: Callable[[Probe], None] | None = None,
    live: LiveView | None = None,
) -> SurveyResult:
    """Run the scene's map campaign (``strategy`` and ``max_probes`` override its keys); with
    ``run_dir``, trial logs under ``logs/`` and the probes in ``probes.jsonl``, read back first
    (a resumed survey carries on from its last probe); with ``live``, each probe's trial and
    the map after it on the live view (``/map/grid``, ``/map/probes``)."""
    c = scene.campaign
    sample = scene.campaign_samples()[0]
    patch = Patch.from_mm((c.patch_mm[0], c.patch_mm[1], c.patch_mm[2], c.patch_mm[3]))
    budget = max_probes if max_probes is not None else c.max_probes
    scale = LENGTH_SCALE_TIPS * stack.sensor.tip_radius  # the narrowest bump the tip sees
    plan = plan_for(
        strategy or c.strategy,
        patch,
        budget,
        seed=seed,
        threshold=c.map_threshold,
        length_scale_max=scale,
    )
    probes = read_probes(run_dir / PROBES_FILE) if run_dir is not None else []
    logs = None if run_dir is None else run_dir / "logs"
    outcomes: list[TrialOutcome] = []
    map_seconds = 0.0
    while True:
        t0 = time.process_time()
        point = plan.next(probes)
        map_seconds += time.process_time() - t0
        if point is None:
            break
        probe, o = _probe_at(scene, stack, probes, point, seed, logs, live)
        probes.append(probe)
        outcomes.append(o)
        if run_dir is not None:
            _append(run_dir / PROBES_FILE, probe)
        if on_probe is not None:
            on_probe(probe)
        if live is not None:
            publish_map(live, probes, patch, c.map_threshold, scale)
    stopped = getattr(plan, "stopped", "") or f"{len(probes)} of {budget} probes"
    t0 = time.process_time()
    summary, note = map_of(probes, patch, c.map_threshold, seed, scale)
    map_seconds += time.process_time() - t0
    lab = sum(p.lab_time for p in probes)
    stopped = stopped + note
    return SurveyResult(
        probes, summary, stopped, lab, map_seconds, truth_of(sample), patch, outcomes, scale
    )


def _probe_at(
    scene: SceneConfig,
    stack: StackConfig,
    probes: list[Probe],
    point: tuple[float, float],
    seed: int,
    logs: Path | None,
    live: LiveView | None,
) -> tuple[Probe, TrialOutcome]:
    """The next probe's trial at ``point``, the stage's travel to it from the last probe."""
    sample = scene.campaign_samples()[0]
    spec = probe_spec(scene, sample, len(probes), point, seed)
    o = run_sim_trial(
        spec,
        moved_scene(scene, sample, point),
        stack,
        transport=scene.transport,
        log_dir=logs,
        live=live,
    )
    last = (0.0, 0.0) if not probes else (probes[-1].x, probes[-1].y)
    travel = math.hypot(point[0] - last[0], point[1] - last[1]) / scene.campaign.stage_speed
    return probe_of(o, point, travel), o


def map_of(
    probes: list[Probe], patch: Patch, threshold: float | None, seed: int, scale: float
) -> tuple[MapSummary | None, str]:
    """The probes' map summarised over ``patch`` (None and why, when it cannot be made)."""
    try:
        fitted = StiffnessMap.fit(probes, seed=seed, length_scale_max=scale)
    except MapError as exc:
        return None, f"; no map: {exc}"
    return summarise(fitted, patch, threshold=threshold, seed=seed), ""


def publish_map(
    live: LiveView, probes: list[Probe], patch: Patch, threshold: float | None, scale: float
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
            out.append(Probe.from_dict(json.loads(line)))
        except ValueError:
            break  # a line cut by a kill: the probe is run again
    return out


def _append(path: Path, probe: Probe) -> None:
    with path.open("a", encoding="utf-8") as fh:
        fh.write(json.dumps(probe.as_dict(), separators=(",", ":")) + "\n")
