"""Campaigns: the list of trials a scene asks for, running them, and Tables I/II from them."""

from __future__ import annotations

import dataclasses
import math
import os
import time
import zlib
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import Executor, as_completed
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from palpate.calibration import calibrated, is_reference
from palpate.campaigns.executors import SerialExecutor, process_pool
from palpate.campaigns.resume import logged_outcome
from palpate.campaigns.shorter import chained
from palpate.config.loader import InputError
from palpate.config.optics import MM
from palpate.config.scene import ORIENTATION_ROLL_DEG, SceneConfig
from palpate.config.schema import StackConfig, TubeConfig
from palpate.estimation.beam.elastica import fast
from palpate.estimation.fits.stiffness import SampleSummary, summarize
from palpate.live import LiveView
from palpate.simulation.trial import Transport, TrialOutcome, TrialSpec, run_sim_trial
from palpate.simulation.world import BENCH_COLUMN


def campaign_trials(scene: SceneConfig, stack: StackConfig, seed: int = 0) -> list[TrialSpec]:
    """Trials in a fixed order; each gets its own seed derived from ``seed`` and its index."""
    c = scene.campaign
    specs: list[TrialSpec] = []
    references = reported_references(scene, seed)

    def add(sample: str, tube: TubeConfig, orientation: str, length_mm: float, rep: int) -> None:
        for speed in c.speeds_mm_per_s():
            at(sample, tube, orientation, length_mm, rep, speed)

    def at(
        name: str, tube: TubeConfig, orientation: str, length: float, rep: int, v: float
    ) -> None:
        s = next(x for x in scene.samples if x.name == name)
        parts = [name, tube.name, orientation, f"L{length:g}"]
        if c.indent_speeds_mm_per_s:
            parts.append(f"v{v:g}")
        if c.repeats > 1:
            parts.append(f"r{rep}")
        specs.append(
            TrialSpec(
                trial_id="-".join(parts),
                kind="robot" if c.on_tubes else "bench",
                sample=s.name,
                modulus=s.modulus,
                poisson=s.poisson,
                tube=tube,
                orientation=orientation,
                roll=math.radians(ORIENTATION_ROLL_DEG[orientation]),
                exposed_length=length * MM,  # the id names it in mm
                seed=seed * 1_000_003 + len(specs),
                reference=references[s.name],
                indent_speed=v * MM if c.indent_speeds_mm_per_s else None,
            )
        )

    for sample in scene.campaign_samples():
        for rep in range(c.repeats):
            if not c.on_tubes:
                for length_mm in c.exposed_lengths_mm:
                    add(sample.name, BENCH_COLUMN, "downward", length_mm, rep)
                continue
            for tube_name in c.tubes:
                tube = stack.tube(tube_name)
                # rolling a straight tube does not change where it points: one trial
                orientations = c.orientations[:1] if tube.tip_angle_deg == 0 else c.orientations
                for orientation in orientations:
                    add(sample.name, tube, orientation, c.exposed_length_mm, rep)
    return specs


def reported_references(scene: SceneConfig, seed: int = 0) -> dict[str, float | None]:
    """Per sample, the reference modulus the lab reports (Pa), or None where it is the truth
    (``fidelity.reference_error_sd`` = 0). The paper's "actual" moduli were themselves measured
    (cylindrical indenter): the truth times ``exp(sd z)``, z standard normal drawn per sample
    from the campaign seed and the sample's name (the same for all its trials, and in every
    scene that has the sample: Table II's phantoms are Table I's)."""
    sd = scene.fidelity.reference_error_sd
    if sd <= 0:
        return {s.name: None for s in scene.samples}
    out: dict[str, float | None] = {}
    for s in scene.samples:
        key = zlib.crc32(s.name.encode())
        z = float(np.random.default_rng([seed, 104_729, key]).standard_normal())
        out[s.name] = s.modulus * math.exp(sd * z)
    return out


@dataclass(frozen=True)
class _Job:
    spec: TrialSpec
    scene: SceneConfig
    stack: StackConfig
    transport: Transport
    log_dir: Path | None
    keep_series: bool
    live: LiveView | None = None  # in-process only: a serial executor


def _run_job(job: _Job) -> TrialOutcome:
    """The job's trial; where it buckled unread, again at each shorter length (``shorter``)."""

    def run(spec: TrialSpec) -> TrialOutcome:
        if job.log_dir is not None and (logged := logged_outcome(job.log_dir, spec, job.stack)):
            return logged  # an attempt that finished before a resumed run
        return run_sim_trial(
            spec,
            job.scene,
            job.stack,
            transport=job.transport,
            log_dir=job.log_dir,
            keep_series=job.keep_series,
            live=job.live,
        )

    outcome = chained(job.spec, job.scene.campaign, run)
    assert outcome is not None  # every attempt runs
    return outcome


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

    ``executor``: any ``concurrent.futures.Executor`` (``palpate.campaigns.executors.open_executor``
    builds process, thread, serial and Dask ones); ``progress`` is called as trials finish."""
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
    # trials of this campaign already done (read back by ``--resume``): their reference trials
    # calibrate the rest as if they had run now
    prior: Sequence[TrialOutcome] = ()
    live: LiveView | None = None  # the live view the trials publish to (a serial executor only)


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
    campaign's end waiting for its last trial while the next campaign's trials queue. Trials on
    a scene's rigid reference samples go first (all campaigns together): they calibrate the
    rig's compliance (``palpate.calibration``), which the campaign's other trials then use."""
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
    results: dict[str, TrialOutcome] = {}
    try:
        first = [(i, r, s) for i, r in enumerate(runs) for s in r.specs if is_reference(r.scene, s)]
        for (i, _, spec), out in zip(first, _execute(first, runs, executor, done), strict=True):
            results[f"{i}/{spec.trial_id}"] = out
        stacks = [
            calibrated(
                r.scene,
                r.stack,
                [results[f"{i}/{s.trial_id}"] for j, _, s in first if j == i]
                + [o for o in r.prior if is_reference(r.scene, o.spec)],
            )
            for i, r in enumerate(runs)
        ]
        calibrated_runs = [
            dataclasses.replace(r, stack=st) for r, st in zip(runs, stacks, strict=True)
        ]
        rest = [
            (i, r, s)
            for i, r in enumerate(calibrated_runs)
            for s in r.specs
            if not is_reference(r.scene, s)
        ]
        for (i, _, spec), out in zip(
            rest, _execute(rest, calibrated_runs, executor, done), strict=True
        ):
            results[f"{i}/{spec.trial_id}"] = out
    finally:
        if own is not None:
            own.shutdown()
    return [
        CampaignResult([results[f"{i}/{s.trial_id}"] for s in r.specs], finished[i])
        for i, r in enumerate(runs)
    ]


def _execute(
    trials: Sequence[tuple[int, CampaignRun, TrialSpec]],
    runs: Sequence[CampaignRun],
    executor: Executor | None,
    done: Callable[[int, TrialOutcome], TrialOutcome],
) -> list[TrialOutcome]:
    """Run ``trials`` (campaign index, its run, spec) on ``executor`` (None or serial: here, in
    order); the outcomes in the order of ``trials``."""
    jobs = [
        (
            i,
            _Job(
                s,
                r.scene,
                r.stack,
                r.transport,
                r.log_dir,
                s.trial_id == runs[i].series_for,
                r.live,
            ),
        )
        for i, r, s in trials
    ]
    if executor is None or isinstance(executor, SerialExecutor):
        return [done(i, _run_job(job)) for i, job in jobs]
    if any(r.live is not None for r in runs):
        raise InputError("--live shows one trial at a time: run with --executor serial")
    futures = {executor.submit(_run_job, job): i for i, job in jobs}
    for fut in as_completed(futures):
        done(futures[fut], fut.result())
    return [fut.result() for fut in futures]


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
    ``method``: "joint" (the contact-point-free fit, the default: over the trials whose
    verdict is ``ok`` only) or "paper" (Eqs. 13-14). Rigid references are left out."""
    by_sample: dict[str, list[TrialOutcome]] = {}
    for o in outcomes:
        if o.calibration is None:
            by_sample.setdefault(o.spec.sample, []).append(o)
    rows = []
    for name, outs in by_sample.items():
        estimates = [_kept(o, method) for o in outs]
        rows.append(
            SampleRow(name, summarize(estimates, outs[0].spec.modulus, outlier_above), len(outs))
        )
    return rows


def _kept(o: TrialOutcome, method: str) -> float | None:
    """The estimate a summary keeps: the joint fit's only when its verdict is ``ok``."""
    if method == "joint" and o.status != "ok":
        return None
    return o.modulus(method)


def median_abs_relative_error(
    outcomes: Iterable[TrialOutcome], method: str = "joint"
) -> float | None:
    """Median |relative error| of ``method``'s estimates (the joint fit's: ``ok`` only)."""
    errs = sorted(
        abs(m - o.spec.modulus) / o.spec.modulus
        for o in outcomes
        if o.calibration is None and (m := _kept(o, method)) is not None
    )
    if not errs:
        return None
    mid = len(errs) // 2
    return errs[mid] if len(errs) % 2 else 0.5 * (errs[mid - 1] + errs[mid])
