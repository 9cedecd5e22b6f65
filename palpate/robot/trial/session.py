"""One trial as a session runs it, on any rig: the same sequence on the bench and in simulation.

Zero the strains at rest, open the trial's log (and its recording), run the state machine to its
end, estimate, and close the log with the estimate and the end record: whatever happens in
between, the log and its recording are closed (``robot.records.log``). What differs between the
bench and the simulator is only what they build before (the rig and a :class:`TrialSetup`)::

    setup = TrialSetup(plan, campaign, stack, estimate=..., log_path=..., header=...)
    done = run_session_trial(rig, clock, setup)
    done.result.state, done.estimate.joint, done.log_path

``palpate.simulation.trial`` (the emulators and the world) and ``palpate.lab.trial`` (the
bench's hardware) are its two callers.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

from ...config.scene import CampaignConfig
from ...config.schema import StackConfig
from ...estimation.trial.estimate import TrialEstimate
from ...sensor.clock import Clock
from ...sensor.strain import StrainChain
from ..guards import Observation
from ..indentation import Prober, State, TrialPlan
from ..records.log import TrialLogWriter
from .record import estimate_record
from .run import Rig, TrialResult, end_record, run_trial
from .setup import detector_for, guards_for
from .tipforce import axial_loads


class ZeroingRig(Rig, Protocol):
    """A :class:`robot.trial.run.Rig` that takes its strain zero at rest (``robot.rig``)."""

    def zero(self) -> StrainChain: ...


@dataclass(frozen=True)
class TrialSetup:
    """What one trial needs besides its rig and clock.

    Attributes:
        plan: where to go (``robot.trial.setup.trial_plan``); campaign: the guards', detector's
            settings; stack: the robot configuration (calibrated compliances included).
        estimate: the trial's estimate from its result (the estimator told what this trial's
            caller knows: the belief, the misalignment probing measured, ...).
        log_path: the trial's log (None: none), its recording beside it with ``mcap``;
            header: the log's header.
        prober: the probing step's builder (a robot that probes first), None without.
        on_tick: called every tick with the observation and the state (a live view, a series).
        on_log: called with the log once it is open (fault injection watches it).
        before_estimate: records written to the log before the estimate (the simulated
            world's truth, which the controller never sees).
        stop: asked every tick whether an operator stop came (``robot.trial.run.run_trial``).
    """

    plan: TrialPlan
    campaign: CampaignConfig
    stack: StackConfig
    estimate: Callable[[TrialResult], TrialEstimate]
    log_path: Path | None = None
    header: dict[str, Any] | None = None
    mcap: bool = True
    prober: Callable[[TrialPlan], Prober] | None = None
    on_tick: Callable[[Observation, State], None] | None = None
    on_log: Callable[[TrialLogWriter], None] | None = None
    before_estimate: Callable[[TrialResult], list[dict[str, Any]]] | None = None
    stop: Callable[[], bool] | None = None


@dataclass(frozen=True)
class SessionTrial:
    """A trial run by :func:`run_session_trial`: how it ran, its estimate and its log."""

    result: TrialResult
    estimate: TrialEstimate
    log_path: str | None


def run_session_trial(rig: ZeroingRig, clock: Clock, setup: TrialSetup) -> SessionTrial:
    """Zero, log, run, estimate, record (the module docstring)."""
    chain = rig.zero()
    with _log(setup) as log:
        guards = guards_for(setup.campaign, setup.stack, rig.tick)
        detector = detector_for(setup.campaign, chain)
        result = run_trial(
            rig,
            clock,
            setup.plan,
            guards,
            detector,
            log,
            on_tick=setup.on_tick,
            prober=setup.prober,
            stop=setup.stop,
        )
        estimate = setup.estimate(result)
        if log is not None:
            # the recording's tip force reuses the rows the estimate's beam states inferred
            log.loads = functools.partial(axial_loads, known=estimate.beam_loads)
            extra = [] if setup.before_estimate is None else setup.before_estimate(result)
            for record in [*extra, estimate_record(estimate), end_record(result)]:
                log.write(record)
    return SessionTrial(result, estimate, None if log is None else str(log.path))


@contextmanager
def _log(setup: TrialSetup) -> Iterator[TrialLogWriter | None]:
    """The trial's log (None without a path), closed however the trial ends."""
    if setup.log_path is None:
        yield None
        return
    header, path = setup.header or {}, setup.log_path
    with TrialLogWriter(path, header, mcap=setup.mcap, loads=axial_loads) as log:
        if setup.on_log is not None:
            setup.on_log(log)
        yield log


__all__ = ["SessionTrial", "TrialSetup", "ZeroingRig", "run_session_trial"]
