"""The world's tissue: speed against error of each fidelity level, and how a viscoelastic
tissue makes the estimate depend on the indentation speed.

Levels, one row each, on the shipped bench scene's phantoms (R = 3.5 mm, 10 mm bonded layers,
nu = 0.45): the closed form (Sneddon x Dimitriadis: the estimator's own family of laws), the FE
linear, the FE neo-Hookean (the shipped scenes' level) and the FE neo-Hookean with a standard
linear solid (``VISCO``: tau = 1 s, E_inf / E_0 = 0.7, a strongly relaxing phantom; PDMS relaxes
far less) at the scene's 0.5 mm/s. Per level:

- the force error against the finest FE (neo-Hookean, mesh resolution 12) over the depths the
  bench trials reach (delta/R <= 0.3): max |F / F_finest - 1| (the viscoelastic level along a
  0.5 mm/s ramp, against the relaxed modulus the scene states);
- its table: build time as recorded when it was generated (``python -m sim.fem.generate``) and
  the read-back (file + interpolant, median);
- the wall time per trial (serial, one trial per phantom at L = 46 mm; three with ``--quick``)
  and, on those trials, the joint fit's median |relative error| and the paper's.

Then the viscoelastic level at indentation speeds 0.1, 0.5 and 2 mm/s: the median signed error
of both estimates against the relaxed modulus (the truth; what a quasi-static test measures).
"""

from __future__ import annotations

import dataclasses
import itertools
import statistics
import time
from collections.abc import Sequence
from typing import Any

import numpy as np

from benchmarks.report import BenchContext, BenchSection, Table, median_time
from palpate.campaigns.campaign import campaign_trials, run_campaign, warm_up
from palpate.config import load, load_stack, resolve
from palpate.config.sample import SampleConfig
from palpate.config.scene import SceneConfig
from palpate.sim.fem import FeTissueLaw, LayerProblem
from palpate.sim.fem.law import curve_from_table
from palpate.sim.fem.table import SHIPPED_DIR, read_table
from palpate.sim.sample_law import fe_problem, relaxation, world_tissue
from palpate.sim.viscoelastic import force_history
from palpate.simulation.trial import TrialOutcome

VISCO = {"relaxation_time_s": 1.0, "relaxed_ratio": 0.7}
SPEEDS_MM_PER_S = (0.1, 0.5, 2.0)
LEVELS: dict[str, dict[str, Any]] = {
    "closed form": {"fidelity": {"tissue_model": "closed-form"}, "sample": {"material": "linear"}},
    "FE linear": {"fidelity": {}, "sample": {"material": "linear"}},
    "FE neo-Hookean": {"fidelity": {}, "sample": {}},
    "FE neo-Hookean + SLS": {"fidelity": {"viscoelastic": True}, "sample": VISCO},
}
MAX_DEPTH_RATIO = 0.3


def level_scene(base: SceneConfig, level: str, speed_mm_per_s: float | None = None) -> SceneConfig:
    """The bench scene at one fidelity level (and indentation speed)."""
    change = LEVELS[level]
    samples = tuple(dataclasses.replace(s, **change["sample"]) for s in base.samples)
    campaign = base.campaign
    if speed_mm_per_s is not None:
        campaign = dataclasses.replace(campaign, indent_speed_mm_per_s=speed_mm_per_s)
    return dataclasses.replace(
        base,
        samples=samples,
        fidelity=dataclasses.replace(base.fidelity, **change["fidelity"]),
        campaign=campaign,
    )


def finest(problem: LayerProblem) -> FeTissueLaw:
    """The reference law: the neo-Hookean table at mesh resolution 12 over the trials' depths
    (solved once into the cache, ~1-2 min)."""
    fine = dataclasses.replace(
        problem, material="neo-hookean", resolution=12, depth_max=MAX_DEPTH_RATIO, n_depths=12
    )
    return FeTissueLaw(fine, 1.0, 1.0)


def force_error(scene: SceneConfig, sample: SampleConfig, tip: float, speed: float) -> float:
    """max |F / F_finest - 1| over delta/R in (0, 0.3] (a ramp at ``speed`` m/s if the sample
    relaxes)."""
    reference = finest(fe_problem(sample, scene.fidelity, tip))
    law = world_tissue(sample, scene.fidelity, tip)
    depths = tip * np.linspace(0.01, MAX_DEPTH_RATIO, 60)
    sls = relaxation(sample, scene.fidelity)
    if sls is None:
        forces = law.force_and_stiffness(depths)[0]
    else:
        times = np.concatenate([[0.0], depths / speed])
        forces = force_history(sls, law, times, np.concatenate([[0.0], depths]))[1:]
    ref = sample.modulus * tip**2 * reference.force_and_stiffness(depths / tip)[0]
    return float(np.max(np.abs(forces / ref - 1.0)))


def table_cost(scene: SceneConfig, sample: SampleConfig, tip: float, repeats: int) -> list[Any]:
    """[recorded build s, read-back ms] of the level's table; '-' for the closed form."""
    if scene.fidelity.tissue_model != "fe":
        return ["-", "-"]
    problem = fe_problem(sample, scene.fidelity, tip)
    stored = read_table(problem, SHIPPED_DIR)
    if stored is None:
        return ["-", "-"]

    def read() -> None:
        table = read_table(problem, SHIPPED_DIR)
        assert table is not None
        curve_from_table(table)

    return [stored.build_seconds, 1e3 * median_time(read, repeats)]


@dataclasses.dataclass(frozen=True)
class TrialStats:
    seconds: float  # median wall time per trial, serial
    joint_abs: float | None
    joint_signed: float | None
    paper_abs: float | None
    paper_signed: float | None
    coverage: float | None


def trial_stats(scene: SceneConfig, ctx: BenchContext) -> TrialStats:
    """One trial per phantom at L = 46 mm (three phantoms with --quick), serially."""
    names = ("S1", "S8", "S11") if ctx.quick else ()
    campaign = dataclasses.replace(scene.campaign, exposed_lengths_mm=(46.0,), samples=names)
    scene = dataclasses.replace(scene, campaign=campaign)
    stack = load_stack(resolve(scene.robot))
    stamps = [time.perf_counter()]
    outcomes = run_campaign(
        campaign_trials(scene, stack, ctx.seed),
        scene,
        stack,
        progress=lambda _: stamps.append(time.perf_counter()),
    )
    per_trial = [b - a for a, b in itertools.pairwise(stamps)]
    joint, paper = _errors(outcomes, "joint"), _errors(outcomes, "paper")
    covered = [o.joint is not None and o.joint.covers(o.spec.modulus) for o in outcomes]
    return TrialStats(
        seconds=statistics.median(per_trial),
        joint_abs=_median([abs(e) for e in joint]),
        joint_signed=_median(joint),
        paper_abs=_median([abs(e) for e in paper]),
        paper_signed=_median(paper),
        coverage=sum(covered) / len(covered) if covered else None,
    )


def _errors(outcomes: Sequence[TrialOutcome], method: str) -> list[float]:
    return [m / o.spec.modulus - 1 for o in outcomes if (m := o.modulus(method)) is not None]


def _median(values: list[float]) -> float | None:
    return statistics.median(values) if values else None


def _pct(x: float | None, signed: bool = False) -> str:
    return "-" if x is None else (f"{100 * x:+.1f} %" if signed else f"{100 * x:.1f} %")


def levels_table(base: SceneConfig, ctx: BenchContext) -> tuple[Table, dict[str, Any]]:
    tip = load_stack(resolve(base.robot)).sensor.tip_radius
    speed = base.campaign.indent_speed_mm_per_s * 1e-3
    rows: list[Sequence[Any]] = []
    summary: dict[str, Any] = {}
    for level in LEVELS:
        scene = level_scene(base, level)
        sample = scene.samples[0]
        error = force_error(scene, sample, tip, speed)
        stats = trial_stats(scene, ctx)
        cost = table_cost(scene, sample, tip, ctx.repeats)
        rows.append(
            [
                level,
                f"{100 * error:.2f} %",
                *cost,
                stats.seconds,
                _pct(stats.joint_abs),
                _pct(stats.paper_abs),
            ]
        )
        summary[level] = {"force_error": error, "table": cost, **dataclasses.asdict(stats)}
    table = Table(
        title="World tissue fidelity levels: speed against error (bench phantoms, 10 mm layers)",
        columns=[
            "level",
            "F vs finest FE",
            "table build s",
            "table read ms",
            "s/trial",
            "joint median",
            "paper median",
        ],
        rows=rows,
        note=(
            "F vs finest FE: max |F/F_ref - 1| at delta/R <= 0.3, F_ref the neo-Hookean table at "
            "mesh resolution 12 (SLS: a 0.5 mm/s ramp against the relaxed modulus); build: as "
            "recorded by python -m sim.fem.generate; trials serial, one per phantom at L = 46 mm"
            f"{' (S1, S8, S11: --quick)' if ctx.quick else ''}, seed {ctx.seed}"
        ),
    )
    return table, summary


def speed_table(base: SceneConfig, ctx: BenchContext) -> tuple[Table, dict[str, Any]]:
    rows: list[Sequence[Any]] = []
    summary: dict[str, Any] = {}
    for speed in SPEEDS_MM_PER_S:
        stats = trial_stats(level_scene(base, "FE neo-Hookean + SLS", speed), ctx)
        rows.append(
            [
                f"{speed:g}",
                stats.seconds,
                _pct(stats.joint_signed, signed=True),
                _pct(stats.coverage),
                _pct(stats.paper_signed, signed=True),
            ]
        )
        summary[f"{speed:g}_mm_per_s"] = dataclasses.asdict(stats)
    table = Table(
        title=(
            "Viscoelastic phantoms (SLS, tau = 1 s, E_inf/E_0 = 0.7): the estimate against the "
            "indentation speed"
        ),
        columns=["speed mm/s", "s/trial", "joint median err", "joint coverage", "paper median err"],
        rows=rows,
        note=(
            "signed errors against the relaxed modulus E_inf (the truth: what a quasi-static test "
            "measures); a fast indentation meets up to E_0 = E_inf / 0.7 (+43 %); the estimators "
            "assume an elastic tissue"
        ),
    )
    return table, summary


def run(ctx: BenchContext) -> BenchSection:
    warm_up()
    base = load(SceneConfig, resolve("scenes/bench.yaml"))
    levels, level_summary = levels_table(base, ctx)
    speeds, speed_summary = speed_table(base, ctx)
    return BenchSection(
        name="tissue",
        tables=[levels, speeds],
        summary={"levels": level_summary, "speeds": speed_summary},
    )
