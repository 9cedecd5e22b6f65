"""Campaigns: the list of trials a scene asks for, running them, and Tables I/II from them."""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import Executor, as_completed
from dataclasses import dataclass
from pathlib import Path

from config.scene import ORIENTATION_ROLL_DEG, SceneConfig
from config.schema import StackConfig
from estimation.elastica import fast
from estimation.stiffness import SampleSummary, summarize
from palpate.executors import SerialExecutor, process_pool
from palpate.simtrial import Transport, TrialOutcome, TrialSpec, run_sim_trial


def campaign_trials(scene: SceneConfig, stack: StackConfig, seed: int = 0) -> list[TrialSpec]:
    """Trials in a fixed order; each gets its own seed derived from ``seed`` and its index."""
    c = scene.campaign
    specs: list[TrialSpec] = []

    def add(sample_name: str, tube: str, orientation: str, length_mm: float, rep: int) -> None:
        s = next(x for x in scene.samples if x.name == sample_name)
        parts = [sample_name, tube, orientation, f"L{length_mm:g}"]
        if c.repeats > 1:
            parts.append(f"r{rep}")
        specs.append(
            TrialSpec(
                trial_id="-".join(parts),
                kind=c.kind,
                sample=s.name,
                modulus=s.modulus,
                poisson=s.poisson,
                tube=tube,
                orientation=orientation,
                roll=math.radians(ORIENTATION_ROLL_DEG[orientation]),
                exposed_length=length_mm * 1e-3,
                seed=seed * 1_000_003 + len(specs),
            )
        )

    for sample in scene.campaign_samples():
        for rep in range(c.repeats):
            if c.kind == "bench":
                for length_mm in c.exposed_lengths_mm:
                    add(sample.name, "straight", "downward", length_mm, rep)
                continue
            for tube_name in c.tubes:
                tube = stack.tube(tube_name)
                # rolling a straight tube does not change where it points: one trial
                orientations = c.orientations[:1] if tube.tip_angle_deg == 0 else c.orientations
                for orientation in orientations:
                    add(sample.name, tube_name, orientation, c.exposed_length_mm, rep)
    return specs


@dataclass(frozen=True)
class _Job:
    spec: TrialSpec
    scene: SceneConfig
    stack: StackConfig
    transport: Transport
    log_dir: Path | None
    keep_series: bool


def _run_job(job: _Job) -> TrialOutcome:
    return run_sim_trial(
        job.spec,
        job.scene,
        job.stack,
        transport=job.transport,
        log_dir=job.log_dir,
        keep_series=job.keep_series,
    )


def run_campaign(
    specs: Sequence[TrialSpec],
    scene: SceneConfig,
    stack: StackConfig,
    *,
    transport: Transport = "fast",
    log_dir: Path | None = None,
    workers: int = 1,
    executor: Executor | None = None,
    series_for: str | None = None,
    progress: Callable[[TrialOutcome], None] | None = None,
) -> list[TrialOutcome]:
    """Run trials (in parallel with ``workers`` > 1 or a given executor); results keep the order
    of ``specs`` and do not depend on the executor (every trial is seeded by its spec).

    ``executor``: any ``concurrent.futures.Executor`` (``palpate.executors.open_executor`` builds
    process, thread, serial and Dask ones); ``progress`` is called as trials finish."""
    run = CampaignRun(specs, scene, stack, transport, log_dir, series_for)
    return run_campaigns([run], workers=workers, executor=executor, progress=progress)[0].outcomes


@dataclass(frozen=True)
class CampaignRun:
    """One scene's trials, as :func:`run_campaigns` takes them."""

    specs: Sequence[TrialSpec]
    scene: SceneConfig
    stack: StackConfig
    transport: Transport = "fast"
    log_dir: Path | None = None
    series_for: str | None = None  # the trial whose force/strain series is kept for the plot


@dataclass(frozen=True)
class CampaignResult:
    outcomes: list[TrialOutcome]
    finished_s: float  # wall seconds from the start of the run to this campaign's last trial


def run_campaigns(
    runs: Sequence[CampaignRun],
    *,
    workers: int = 1,
    executor: Executor | None = None,
    progress: Callable[[TrialOutcome], None] | None = None,
) -> list[CampaignResult]:
    """Run several campaigns through one executor, as :func:`run_campaign` runs one.

    Every trial of every campaign is submitted at once, so the workers do not idle at a
    campaign's end waiting for its last trial while the next campaign's trials queue."""
    jobs = [
        (i, _Job(s, r.scene, r.stack, r.transport, r.log_dir, s.trial_id == r.series_for))
        for i, r in enumerate(runs)
        for s in r.specs
    ]
    warm_up()  # before the pool forks, so every worker inherits the built tables
    t0 = time.perf_counter()
    finished = [0.0] * len(runs)

    def done(i: int, out: TrialOutcome) -> TrialOutcome:
        finished[i] = time.perf_counter() - t0
        if progress is not None:
            progress(out)
        return out

    own: Executor | None = None
    if executor is None and workers > 1:
        own = executor = process_pool(workers)
    try:
        if executor is None or isinstance(executor, SerialExecutor):
            outcomes = [done(i, _run_job(job)) for i, job in jobs]
        else:
            futures = {executor.submit(_run_job, job): i for i, job in jobs}
            for fut in as_completed(futures):
                done(futures[fut], fut.result())
            outcomes = [fut.result() for fut in futures]
    finally:
        if own is not None:
            own.shutdown()
    results, start = [], 0
    for i, r in enumerate(runs):
        results.append(CampaignResult(outcomes[start : start + len(r.specs)], finished[i]))
        start += len(r.specs)
    return results


def warm_up() -> None:
    """Build the process-wide tables a trial needs (the elastica surrogate, fitted once from the
    closed form: about 0.5 s) in this process. Forked pool workers then start with them."""
    fast.surrogate()


def default_workers() -> int:
    return max(1, min(2, os.cpu_count() or 1))


@dataclass(frozen=True)
class SampleRow:
    sample: str
    summary: SampleSummary
    trials: int


def summarize_campaign(
    outcomes: Iterable[TrialOutcome], outlier_above: float, method: str = "joint"
) -> list[SampleRow]:
    """Per sample: mean, RMSE, IQR and relative error of the estimates (Tables I/II), by
    ``method``: "joint" (the contact-point-free fit, the default) or "paper" (Eqs. 13-14)."""
    by_sample: dict[str, list[TrialOutcome]] = {}
    for o in outcomes:
        by_sample.setdefault(o.spec.sample, []).append(o)
    rows = []
    for name, outs in by_sample.items():
        estimates = [o.modulus(method) for o in outs]
        rows.append(
            SampleRow(name, summarize(estimates, outs[0].spec.modulus, outlier_above), len(outs))
        )
    return rows


def median_abs_relative_error(
    outcomes: Iterable[TrialOutcome], method: str = "joint"
) -> float | None:
    errs = sorted(
        abs(m - o.spec.modulus) / o.spec.modulus
        for o in outcomes
        if (m := o.modulus(method)) is not None
    )
    if not errs:
        return None
    mid = len(errs) // 2
    return errs[mid] if len(errs) % 2 else 0.5 * (errs[mid - 1] + errs[mid])
