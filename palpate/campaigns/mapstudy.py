"""A map study: many seeded worlds, each surveyed by every plan, scored against its truth.

Each world is the map scene's sample with its inclusion moved to a random point of the patch
(uniform, the inclusion's footprint inside the patch), seeded by the world's index; the same
worlds for every plan, so the plans are compared pair by pair. Beside them as many homogeneous
worlds (the scene's inclusion taken out) surveyed by the active plan: its false alarms. Each
survey is a whole run of ``campaigns.survey`` (every probe a simulated trial); surveys run in
parallel over ``workers`` processes. The summary per plan: detection, the centre's error, the
boundary's sensitivity, specificity and error (the area where the estimated region and the
true footprint disagree, mm^2), probes and lab time; for the raster, each budget given::

    rows = run_map_study(scene, stack, worlds=20, plans=[("active", 30), ("raster", 36)])
    table = summarise_study(rows)
"""

from __future__ import annotations

import concurrent.futures
import dataclasses
import math
from collections.abc import Callable, Sequence
from typing import Any, Literal

import numpy as np

from palpate.config.sample import InclusionConfig, SampleConfig
from palpate.config.scene import SceneConfig
from palpate.config.schema import StackConfig

from .executors import process_pool
from .survey import run_survey

Plan = tuple[str, int]  # (strategy, probe budget)


def world_scene(
    scene: SceneConfig, index: int, seed: int, plain: bool = False, whole: bool = False
) -> SceneConfig:
    """World ``index``: the scene's one sample with its inclusion at a seeded random point of
    the patch (or taken out, ``plain``; or, ``whole``, its inclusions drawn whole:
    :func:`drawn_inclusions`)."""
    sample = scene.campaign_samples()[0]
    if plain:
        moved = dataclasses.replace(sample, inclusions=())
    elif whole:
        rng = np.random.default_rng([seed, index, 57])
        drawn = drawn_inclusions(sample, scene.campaign.patch_mm, rng)
        moved = dataclasses.replace(sample, inclusions=drawn)
    else:
        inc = sample.inclusions[0]
        x0, y0, x1, y1 = scene.campaign.patch_mm
        r = inc.radius_mm
        rng = np.random.default_rng([seed, index])
        x, y = rng.uniform([x0 + r, y0 + r], [x1 - r, y1 - r])
        centre = (float(x), float(y), inc.center_mm[2])
        moved = dataclasses.replace(
            sample, inclusions=(dataclasses.replace(inc, center_mm=centre),)
        )
    return dataclasses.replace(
        scene, samples=(moved,), campaign=dataclasses.replace(scene.campaign, samples=())
    )


SIZES_MM = (2.0, 4.0)  # radii drawn (uniform)
CONTRASTS = (3.0, 10.0)  # stiff contrasts drawn (log-uniform)
SOFT_SHARE, SOFT_CONTRAST = 0.25, 0.3  # a quarter of them soft, at 0.3x
TOP_MM = (0.5, 2.0)  # the sphere's top under the surface (uniform): within what the tip sees
APART_CONTACTS = 2.0  # footprints at least this many contact radii apart
CONTACT_MM = 1.8  # the paper's tip's contact radius on the S8 phantom (docs/maps.md)


def drawn_inclusions(
    sample: SampleConfig, patch_mm: tuple[float, ...], rng: np.random.Generator
) -> tuple[InclusionConfig, ...]:
    """A world drawn whole: 0-3 spheres (:data:`SIZES_MM`, :data:`CONTRASTS`, a share soft),
    each footprint inside the patch and :data:`APART_CONTACTS` contact radii clear of the
    others (a draw that cannot be placed in 200 tries is left out)."""
    x0, y0, x1, y1 = patch_mm
    out: list[InclusionConfig] = []
    for _ in range(int(rng.integers(0, 4))):
        r = float(rng.uniform(*SIZES_MM))
        soft = bool(rng.random() < SOFT_SHARE)
        contrast = SOFT_CONTRAST if soft else float(np.exp(rng.uniform(*np.log(CONTRASTS))))
        depth = float(rng.uniform(*TOP_MM)) + r
        for _try in range(200):
            x, y = (float(v) for v in rng.uniform([x0 + r, y0 + r], [x1 - r, y1 - r]))
            clear = all(
                math.hypot(x - o.center_mm[0], y - o.center_mm[1])
                >= r + o.radius_mm + APART_CONTACTS * CONTACT_MM
                for o in out
            )
            if clear:
                out.append(
                    InclusionConfig(
                        center_mm=(x, y, depth),
                        radius_mm=r,
                        modulus_kpa=contrast * sample.modulus_kpa,
                    )
                )
                break
    return tuple(out)


def survey_row(
    scene: SceneConfig,
    stack: StackConfig,
    plan: Plan,
    index: int,
    seed: int,
    plain: bool,
    whole: bool = False,
    through: Literal["stage", "robot"] | None = None,
) -> dict[str, Any]:
    """One survey of world ``index`` by ``plan`` (its probes reaching the patch ``through``
    the stage or the robot; None: as the scene says): its scores and costs (picklable)."""
    strategy, budget = plan
    world = world_scene(scene, index, seed, plain, whole)
    if through is not None:
        world = dataclasses.replace(
            world, campaign=dataclasses.replace(world.campaign, map_through=through)
        )
    result = run_survey(
        world, stack, seed=seed * 1000 + index, strategy=strategy, max_probes=budget
    )
    s = result.summary
    row: dict[str, Any] = {
        "strategy": strategy,
        "budget": budget,
        "world": index,
        "plain": plain,
        "whole": whole,
        "through": world.campaign.map_through,
        "probes": len(result.probes),
        "lab_time_s": result.lab_time,
        "map_s_per_probe": result.map_seconds / max(len(result.probes), 1),
        "found": bool(s is not None and s.found),
        "truth": None if result.truth is None else result.truth.as_dict()["inclusions"],
        "inclusions": [] if s is None else [i.as_dict() for i in s.inclusions],
        **result.scores(),
        "probe_list": [p.record() for p in result.probes],  # to summarise again (SI, exact)
    }
    return row


def run_map_study(
    scene: SceneConfig,
    stack: StackConfig,
    *,
    worlds: int,
    plans: Sequence[Plan],
    seed: int = 0,
    workers: int = 1,
    progress: Callable[[dict[str, Any]], None] | None = None,
    whole: bool = False,
    throughs: Sequence[Literal["stage", "robot"]] = (),
) -> list[dict[str, Any]]:
    """Every plan on every world, and the active plan on as many homogeneous worlds; with
    ``whole``, every plan on worlds drawn whole (:func:`drawn_inclusions`: some of them hold
    none, so no homogeneous worlds beside them); each of it once for each way of ``throughs``
    (``stage``, ``robot``: the same worlds side by side; empty: the scene's way)."""
    jobs = [(plan, k, False) for plan in plans for k in range(worlds)]
    active = next((p for p in plans if p[0].startswith("active")), None)
    if active is not None and not whole:
        jobs += [(active, k, True) for k in range(worlds)]
    ways: Sequence[Literal["stage", "robot"] | None] = tuple(throughs) or (None,)
    rows: list[dict[str, Any]] = []
    with process_pool(max(1, workers)) as pool:
        futures = [
            pool.submit(survey_row, scene, stack, plan, k, seed, plain, whole, way)
            for way in ways
            for plan, k, plain in jobs
        ]
        for future in concurrent.futures.as_completed(futures):
            row = future.result()
            rows.append(row)
            if progress is not None:
                progress(row)
    return sorted(
        rows, key=lambda r: (r["through"], r["plain"], r["strategy"], r["budget"], r["world"])
    )


def summarise_study(rows: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per plan (and the homogeneous worlds apart): the medians and rates the study reports."""
    groups: dict[tuple[str, str, int, bool], list[dict[str, Any]]] = {}
    for r in rows:
        way = r.get("through", "stage")
        groups.setdefault((way, r["strategy"], r["budget"], r["plain"]), []).append(r)
    out = []
    for (way, strategy, budget, plain), rs in sorted(
        groups.items(), key=lambda g: (g[0][0] != "stage", g[0][3], g[0][1], g[0][2])
    ):
        line: dict[str, Any] = {"strategy": strategy, "budget": budget, "worlds": len(rs)}
        if way != "stage":
            line["through"] = way
            line.update(normal_lines(rs))
        line["probes_median"] = _median([r["probes"] for r in rs])
        line["lab_time_s_median"] = _median([r["lab_time_s"] for r in rs])
        line["map_s_per_probe_max"] = max(r["map_s_per_probe"] for r in rs)
        if any(r.get("whole") for r in rs):
            line.update(whole_lines(rs))
        elif plain:
            line["homogeneous"] = True
            line["false_alarms"] = sum(r["found"] for r in rs)
        else:
            line["detected"] = sum(r["found"] for r in rs)
            for key in ("center_in_ci", "radius_in_ci"):  # the intervals' coverage
                line[key] = sum(bool(r.get(key)) for r in rs if r["found"])
            for key in ("center_error_mm", "sensitivity", "specificity", "boundary_error_mm2"):
                line[f"{key}_median"] = _median([r[key] for r in rs if r.get(key) is not None])
        out.append(line)
    return out


def whole_lines(rows: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """The rates of a study on worlds drawn whole: every true inclusion found (of its kind),
    worlds with a false one, the centre's and the depth's error and interval per found
    inclusion (the depth where it was read), soft ones read as soft."""
    per = [i for r in rows for i in r.get("per_inclusion", [])]
    found = [i for i in per if i["found"]]
    soft = [i for i in per if i["kind"] == "soft"]
    deep = [i for i in found if "depth_error_mm" in i]
    return {
        "inclusions_true": len(per),
        "inclusions_found": len(found),
        "worlds_with_a_false_one": sum(r.get("false_inclusions", 0) > 0 for r in rows),
        "center_error_mm_median": _median([i["center_error_mm"] for i in found]),
        "center_in_ci": sum(i["center_in_ci"] for i in found),
        "depth_read": len(deep),
        "depth_error_mm_median": _median([i["depth_error_mm"] for i in deep]),
        "depth_in_ci": sum(i["depth_in_ci"] for i in deep),
        "soft_true": len(soft),
        "soft_found_as_soft": sum(i["found"] for i in soft),
    }


def normal_lines(rows: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """How square on a way's probes pressed, over its surveys (``maps.probes.normal_scores``)."""
    known = [r for r in rows if "normal_error_max_deg" in r]
    if not known:
        return {}
    return {
        "normal_error_max_deg": max(r["normal_error_max_deg"] for r in known),
        "probes_off_normal": sum(r["probes_off_normal"] for r in known),
        "off_normal_unflagged": sum(r["off_normal_unflagged"] for r in known),
    }


def _median(values: Sequence[float]) -> float | None:
    return float(np.median(values)) if values else None


def wilson(k: int, n: int, z: float = 1.96) -> tuple[float, float]:
    """The Wilson 95 % interval of a rate k / n."""
    if n == 0:
        return (0.0, 1.0)
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return (max(0.0, centre - half), min(1.0, centre + half))
