"""A session on the bench, as ``palpate trial`` runs it and the tests drive it on the emulators'
pseudo-terminals: the bench opened (its ports from the file unless given), the bench file's
trials run, then its map on the x-y stage (``services.benchmap``), the hardware closed whatever
happened; and the session's results: per-sample rows, the rigid reference's calibration and
the map, written into the session's folder. The command prints.

Usage::

    loaded = with_ports(load_bench("bench.yaml"), servo_pty, board_pty)
    trials, survey = plan_session(loaded, None)           # palpate.lab.plan
    outcomes, mapped = run_map_session(loaded, trials, survey, log_dir, clock=clock)
    done = session_results(loaded, log_dir, outcomes, mapped, CampaignResults(log_dir))
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from palpate.calibration import calibrate
from palpate.config.bench import LoadedBench
from palpate.lab.hardware import open_hardware
from palpate.lab.trial import SKIPPED, BenchOutcome, BenchTrial, Session, run_bench_trials
from palpate.live import live_view
from palpate.reports.results import CampaignResults
from palpate.sensor.clock import Clock
from palpate.sensor.reader import SerialLike
from palpate.services.benchsamples import bench_samples

if TYPE_CHECKING:  # the maps import scikit-learn: only when a bench file maps
    from palpate.campaigns.surveyloop import SurveyResult


def run_session(
    loaded: LoadedBench, trials: list[BenchTrial], log_dir: Path, **options: Any
) -> list[BenchOutcome]:
    """Open the bench (ports from the file unless given) and run ``trials``; torque is off and
    the ports closed on return, whatever happened: :func:`run_map_session` without a map
    (``options``: its keywords). Tests pass the emulators' ptys and a virtual clock (with
    ``sync_to_clock``)."""
    outcomes, _ = run_map_session(loaded, trials, None, log_dir, **options)
    return outcomes


def run_map_session(
    loaded: LoadedBench,
    trials: list[BenchTrial],
    survey: BenchTrial | None,
    log_dir: Path,
    *,
    servo_port: str | Any | None = None,
    board_port: str | SerialLike | None = None,
    clock: Clock | None = None,
    sync_to_clock: bool = False,
    progress: Callable[[BenchOutcome], None] | None = None,
    live: int | None = None,
) -> tuple[list[BenchOutcome], SurveyResult | None]:
    """Open the bench (ports from the file unless given: the emulators' ptys in tests, with a
    virtual clock and ``sync_to_clock``; ``live``: the live view's port, ``--live``), run
    ``trials``, then, with a ``survey`` (the trial each probe repeats,
    ``palpate.services.benchmap.plan_bench_map``), the bench file's map on the x-y stage with the
    compliance the trials calibrated: the trials' outcomes and the map (None without one, or
    when a trial before it ended the session)."""
    key = str(loaded.path)
    with (
        open_hardware(
            loaded.stack,
            servo_port=servo_port,
            board_port=board_port,
            clock=clock,
            servo_key=f"servos.port in {key}",
            board_key=f"board.port in {key}",
        ) as hw,
        live_view(live, loaded.stack) as view,
    ):
        session = Session(loaded.stack)
        outcomes = run_bench_trials(
            hw,
            trials,
            loaded,
            log_dir,
            sync_to_clock=sync_to_clock,
            progress=progress,
            live=view,
            session=session,
        )
        if survey is None or any(o.state == SKIPPED for o in outcomes):
            return outcomes, None
        from palpate.services.benchmap import run_bench_map

        result = run_bench_map(
            hw,
            survey,
            loaded,
            session.stack,
            log_dir,
            sync_to_clock=sync_to_clock,
            progress=progress,
            live=view,
        )
        return outcomes, result


def with_ports(loaded: LoadedBench, servo: str | None, board: str | None) -> LoadedBench:
    """``loaded`` with the servo and board ports replaced where given."""
    stack = loaded.stack
    if servo is not None:
        stack = dataclasses.replace(stack, servos=dataclasses.replace(stack.servos, port=servo))
    if board is not None:
        stack = dataclasses.replace(stack, board=dataclasses.replace(stack.board, port=board))
    return dataclasses.replace(loaded, stack=stack)


@dataclass(frozen=True)
class SessionResults:
    """A finished session: every trial's and probe's outcome, the per-sample rows (trials, not
    probes), the calibration found on the rigid reference (rig key: interval m/N), the map
    (None without one), the ``--json`` payload and the results files written."""

    log_dir: Path
    outcomes: list[BenchOutcome]
    samples: list[dict[str, Any]]
    calibration: dict[str, tuple[float, float]]
    mapped: SurveyResult | None
    payload: dict[str, Any]
    files: list[Path]


def session_results(
    loaded: LoadedBench,
    log_dir: Path,
    outcomes: list[BenchOutcome],
    mapped: SurveyResult | None,
    results: CampaignResults,
) -> SessionResults:
    """The session's results, their files written in ``log_dir`` (``results``)."""
    samples = bench_samples(outcomes, loaded.bench.campaign.outlier_above)  # the trials, not probes
    found = calibrate(
        (o.trial.stage.rig_key, o.calibration) for o in outcomes if o.calibration is not None
    )
    probes = [] if mapped is None else [o for o in mapped.outcomes if o is not None]
    outcomes = outcomes + probes  # every trial's row; the samples' statistics leave probes out
    trial_rows = [o.as_dict() for o in outcomes]
    payload: dict[str, Any] = {
        "bench": str(loaded.path),
        "log_dir": str(log_dir),
        "trials": trial_rows,
        "samples": samples,
        "calibration": {k: [lo * 1e3, hi * 1e3] for k, (lo, hi) in found.items()},
    }
    if mapped is not None:
        payload["map"] = _map_results(mapped, loaded, log_dir)
    files = results.finish(trial_rows, samples, payload) if outcomes else []
    return SessionResults(log_dir, outcomes, samples, found, mapped, payload, files)


def _map_results(mapped: SurveyResult, loaded: LoadedBench, log_dir: Path) -> dict[str, Any]:
    """The map's files in the session folder (``map.json``, ``.mcap``, ``.png``); its payload."""
    from palpate.reports.mapresults import write_map_results

    m = loaded.bench.map
    assert m is not None
    info = {"target": m.target, "strategy": m.strategy, "max_probes": m.max_probes}
    return write_map_results(
        mapped, log_dir, info, threshold=m.threshold, title=f"map at {m.target}", plots=True
    )
