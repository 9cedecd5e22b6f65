"""Simulated campaigns, as ``palpate sim`` and :func:`palpate.api.simulate` run them: every scene
loaded and checked before a trial moves, each campaign's run folder (a new one, or the newest one
resumed, locked while this process writes there), the trials of every scene through one pool,
and each campaign's report with its results files and figures. The caller prints.

Usage::

    request = CampaignRequest((resolve("scenes/bench.yaml"),), limit=2, plots=False)
    with opened(request) as campaigns:
        run(campaigns, request)
        done = [finish(c, request) for c in campaigns]
    done[0].report.as_dict()["trials"]
"""

from __future__ import annotations

import contextlib
import dataclasses
import logging
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from palpate.campaigns.campaign import (
    CampaignRun,
    campaign_trials,
    run_campaigns,
    summarize_campaign,
)
from palpate.campaigns.executors import open_executor
from palpate.campaigns.resume import resume_outcomes
from palpate.campaigns.runs import fingerprint, locked, new_run_dir, resumable, write_run_info
from palpate.config import InputError, load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.config.schema import StackConfig
from palpate.reports.payload import CampaignReport, campaign_report
from palpate.reports.results import CampaignResults
from palpate.simulation.preflight import check_campaign, check_reachable
from palpate.simulation.trial import Transport, TrialOutcome, TrialSpec

if TYPE_CHECKING:
    from palpate.live import LiveView

log = logging.getLogger(__name__)

Progress = Callable[[TrialOutcome], None]


@dataclass(frozen=True)
class CampaignRequest:
    """What to run: the scenes' YAML files and how.

    Attributes:
        scenes: the scene files, run through one pool in this order.
        out: each campaign's run folder is a new ``out/<scene>/<date-time>/`` (or, with
            ``resume``, the newest one of the same run).
        limit: run only the first ``limit`` trials of each scene.
        wire: servos and board over pseudo-terminals (the hardware path) instead of the
            scene's transport.
        mcap: an MCAP recording beside each trial's log; plots: the campaign's figures.
        live: the live view's publisher (the command opens it), None for none.
    """

    scenes: tuple[Path, ...]
    seed: int = 0
    out: Path = Path("out/sim")
    workers: int = 1
    executor: str = "process"
    scheduler: str | None = None
    wire: bool = False
    limit: int | None = None
    resume: bool = False
    mcap: bool = True
    plots: bool = True
    live: LiveView | None = None

    @property
    def pool(self) -> tuple[str, int]:
        """The executor and workers the trials run on (serial, one, for the live view)."""
        return ("serial", 1) if self.live is not None else (self.executor, max(1, self.workers))


@dataclass
class Campaign:
    """One scene's campaign, loaded and checked before anything runs."""

    label: str  # the scene's file (what an error names)
    scene: SceneConfig
    stack: StackConfig
    specs: list[TrialSpec]
    transport: Transport
    run_dir: Path = Path()
    done: dict[str, TrialOutcome] = field(default_factory=dict)  # read back on resume
    outcomes: list[TrialOutcome] = field(default_factory=list)
    wall: float = 0.0
    results: CampaignResults | None = None

    @property
    def log_dir(self) -> Path:
        return self.run_dir / "logs"

    def to_run(self) -> list[TrialSpec]:
        return [s for s in self.specs if s.trial_id not in self.done]


@dataclass(frozen=True)
class CampaignDone:
    """A finished campaign: its report, and the figures and results files written."""

    campaign: Campaign
    report: CampaignReport
    figures: list[str]
    files: list[Path]
    pool: tuple[str, int]  # the executor and workers it ran on


def prepare(path: Path, request: CampaignRequest) -> Campaign:
    """The scene at ``path`` loaded and its campaign checked (an ``InputError`` names the file)."""
    scene = load(SceneConfig, path)
    robot = resolve(scene.robot)
    return prepared(scene, load_stack(robot), request, str(path), str(robot))


def prepared(
    scene: SceneConfig,
    stack: StackConfig,
    request: CampaignRequest,
    label: str = "scene",
    robot: str = "robot",
) -> Campaign:
    """A loaded scene's campaign checked against the robot it runs on."""
    if not request.mcap:
        scene = dataclasses.replace(scene, mcap=False)
    check_campaign(scene, stack, label, robot)
    specs = campaign_trials(scene, stack, request.seed)[: request.limit]
    if not specs:
        raise InputError(f"{label}: the campaign has no trials")
    check_reachable(specs, stack, label, robot)
    return Campaign(label, scene, stack, specs, "wire" if request.wire else scene.transport)


@contextlib.contextmanager
def opened(request: CampaignRequest) -> Iterator[list[Campaign]]:
    """Every scene prepared (a bad one stops the run before any trial moves), then each
    campaign's run folder opened and locked until the block ends."""
    campaigns = [prepare(path, request) for path in request.scenes]
    with contextlib.ExitStack() as locks:
        for c in campaigns:
            _open_run(c, request, locks)
        yield campaigns


def in_folder(c: Campaign, folder: Path) -> None:
    """The campaign's logs (``folder/logs``) and results files in ``folder`` itself: no run
    folder under it, no lock (the Python API's ``out``)."""
    c.run_dir = folder
    c.results = CampaignResults(folder)
    c.log_dir.mkdir(parents=True, exist_ok=True)


def _open_run(c: Campaign, request: CampaignRequest, locks: contextlib.ExitStack) -> None:
    """The campaign's run folder: a new one, or on resume the newest one of the same run, whose
    complete trials are read back."""
    info = {
        "scene": c.scene.name,
        "config": fingerprint(c.scene, c.stack),
        "seed": request.seed,
        "limit": request.limit,
        "transport": c.transport,
        "trials": len(c.specs),
    }
    base = request.out / c.scene.name
    if request.resume:
        c.run_dir = locks.enter_context(locked(resumable(base, info)))
        c.done = resume_outcomes(c.log_dir, c.specs, c.stack, c.scene.campaign)
        c.results = CampaignResults(c.run_dir)
        c.results.start(o.as_dict() for s in c.specs if (o := c.done.get(s.trial_id)))
        log.info(
            "resuming %s: %d of %d trials already complete", c.run_dir, len(c.done), len(c.specs)
        )
    else:
        c.run_dir = locks.enter_context(locked(new_run_dir(base)))
        write_run_info(c.run_dir, info)
        c.results = CampaignResults(c.run_dir)
    c.log_dir.mkdir(exist_ok=True)


def run(
    campaigns: Sequence[Campaign], request: CampaignRequest, progress: Progress | None = None
) -> float:
    """Every campaign's remaining trials through one pool; fills each one's outcomes (in its
    trials' order, resumed ones included) and wall time. Returns the wall time of all (s)."""
    by_logs = {c.log_dir: c for c in campaigns if c.results is not None}

    def finished(o: TrialOutcome) -> None:
        c = by_logs.get(Path(o.log_path).parent) if o.log_path else None
        if c is not None and c.results is not None:  # each trial's row on disk as it finishes
            c.results.add(o.as_dict())
        if progress is not None:
            progress(o)

    runs = [
        CampaignRun(
            c.to_run(),
            c.scene,
            c.stack,
            c.transport,
            c.log_dir if c.results is not None else None,
            _series_for(c, request),
            prior=list(c.done.values()),
            live=request.live,
        )
        for c in campaigns
    ]
    executor, workers = request.pool  # the live view shows one trial at a time
    t_all = time.perf_counter()
    with open_executor(executor, workers, request.scheduler) as pool:
        results = run_campaigns(runs, executor=pool, progress=finished)
    before = 0.0
    for c, r in zip(campaigns, results, strict=True):
        # the pool overlaps campaigns: each is charged the wall time since the previous finished
        c.wall, before = max(r.finished_s - before, 1e-9), r.finished_s
        # by the spec each ran for (a retry's outcome names its own length: campaigns.shorter)
        ran = {s.trial_id: o for s, o in zip(c.to_run(), r.outcomes, strict=True)}
        c.outcomes = [ran.get(s.trial_id) or c.done[s.trial_id] for s in c.specs]
    return time.perf_counter() - t_all


def _series_for(c: Campaign, request: CampaignRequest) -> str | None:
    """The trial whose force and strain series the traces plot shows (the first), if it runs."""
    first = c.specs[0].trial_id
    return None if not request.plots or c.results is None or first in c.done else first


def finish(c: Campaign, request: CampaignRequest) -> CampaignDone:
    """The campaign's report; with a run folder its figures (unless ``plots`` is off) and
    results files (``palpate.reports.results``) written there."""
    figures: list[str] = []
    if request.plots and c.results is not None:
        from palpate.reports.plots import campaign_figures  # matplotlib: only for figures

        rows = summarize_campaign(c.outcomes, c.scene.campaign.outlier_above)
        figures = campaign_figures(c.outcomes, rows, c.run_dir, c.scene.name)
    run_info = {
        "run_dir": None if c.results is None else str(c.run_dir),
        "log_dir": None if c.results is None else str(c.log_dir),
        "transport": c.transport,
        "seed": request.seed,
    }
    report = campaign_report(
        c.scene, c.stack, c.outcomes, run=run_info, wall=c.wall, figures=figures
    )
    files: list[Path] = []
    if c.results is not None:
        payload = report.as_dict()
        files = c.results.finish(payload["trials"], report.samples, payload)
    return CampaignDone(c, report, figures, files, request.pool)
