"""Estimation when the world is not what the estimator is told: the mismatch campaigns.

Each shipped scene in ``config/scenes/mismatch/`` changes one thing about the world against the
nominal campaign (10 mm bonded layers, nu = 0.45, FBG noise 1 pm, rigid tubes, moduli
150-2600 kPa): the layer thickness (5 or 20 mm, believed 5-20 mm; unknown), the bonding
(sliding, bonding unknown), the Poisson ratio (0.40-0.49, believed 0.40-0.50), the beam's
imperfection (w0/L = 0.005, never told), the FBG noise (3 pm), compliant tube tips (10 N/mm,
calibrated on a rigid reference in the same scene), and 60 kPa tissue (too soft for the sensor).
Two more run the same worlds with a wrong point belief (bonded; nu = 0.45), for what it costs.

Per case: the trials' verdicts (ok / suspect / none), the median and worst |relative error| over
``ok`` trials, the median over every trial with a number, the 95 % intervals' coverage over
every trial with a number, and the joint fit's median wall time per trial. All scenes run
through one process pool (2 workers); ``--quick`` runs every second trial.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from benchmarks.report import BenchContext, BenchSection, Table
from palpate.calibration import is_reference
from palpate.campaigns.campaign import CampaignRun, campaign_trials, default_workers, run_campaigns
from palpate.config import load, load_stack, resolve
from palpate.config.loader import CONFIG_DIR
from palpate.config.scene import SceneConfig
from palpate.reports.verdicts import Tally, counts_column, tally

CASES: tuple[tuple[str, str], ...] = (
    ("nominal", "the world is what the estimator is told"),
    ("thin", "5 mm layers, believed 5-20 mm"),
    ("thick", "20 mm layers, believed 5-20 mm"),
    ("thickness-unknown", "6-30 mm layers, thickness unknown"),
    ("sliding", "sliding layers, bonding unknown"),
    ("poisson", "nu 0.40-0.49, believed 0.40-0.50"),
    ("imperfection", "beam bow w0/L 0.005, not told"),
    ("noise3pm", "FBG noise 3 pm"),
    ("compliance", "tube tips 10 N/mm, calibrated on a rigid reference"),
    ("soft60", "60 kPa tissue, default sensor: every trial none"),
    ("sliding-believed-bonded", "wrong point belief: bonded (not a target)"),
    ("poisson-believed-045", "wrong point belief: nu = 0.45 (not a target)"),
)
SCENE_DIR = CONFIG_DIR / "scenes" / "mismatch"


def _run(name: str, ctx: BenchContext) -> CampaignRun:
    scene = load(SceneConfig, SCENE_DIR / f"{name}.yaml")
    stack = load_stack(resolve(scene.robot))
    specs = campaign_trials(scene, stack, ctx.seed)
    if ctx.quick:  # every second trial, but every rigid reference (the calibration)
        specs = [s for i, s in enumerate(specs) if i % 2 == 0 or is_reference(scene, s)]
    return CampaignRun(specs, scene, stack)


def _pct(x: float | None) -> str:
    return "-" if x is None else f"{100 * x:.1f} %"


def _row(name: str, what: str, t: Tally) -> list[Any]:
    cover = "-" if t.coverage is None else f"{t.covered}/{t.numbers} ({100 * t.coverage:.0f} %)"
    return [
        name,
        what,
        t.trials,
        counts_column(t),
        _pct(t.median_ok),
        _pct(t.worst_ok),
        _pct(t.median_all),
        cover,
        "-" if t.ms_per_trial is None else f"{t.ms_per_trial:.0f}",
    ]


def run(ctx: BenchContext) -> BenchSection:
    runs = [_run(name, ctx) for name, _ in CASES]
    results = run_campaigns(runs, workers=default_workers())
    tallies = {name: tally(r.outcomes) for (name, _), r in zip(CASES, results, strict=True)}
    table = Table(
        title="Estimation when the world differs from what the fit is told "
        "(config/scenes/mismatch/*.yaml)",
        columns=[
            "case",
            "world vs belief",
            "trials",
            "ok/sus/none",
            "median ok",
            "worst ok",
            "median all",
            "95% CI cover",
            "fit ms",
        ],
        rows=[_row(name, what, tallies[name]) for name, what in CASES],
        note=(
            f"seed {ctx.seed}{', every second trial (--quick)' if ctx.quick else ''}; errors "
            "are |relative errors| of the joint fit; 'all' and coverage over every trial with a "
            "number (ok and suspect); rigid references (calibration) are not counted"
        ),
    )
    summary = {
        name: dataclasses.asdict(t) | {"coverage": t.coverage} for name, t in tallies.items()
    }
    return BenchSection("estimation", tables=[table], figures=[], summary=summary)
