"""Scripted trials on the bench: stored poses -> trial plans -> the same trial loop as simulation.

:func:`plan_bench_trials` (``palpate.lab.plan``) turns the bench file's trial list and the
stored targets into :class:`robot.indentation.TrialPlan` s, checked against the drive's limits
before anything moves. :func:`run_bench_trials` runs them in order on opened interfaces
(:mod:`palpate.lab.hardware`) with :func:`robot.trial.run.run_trial` and the
:class:`robot.rig.ServoFbgRig`, writes one crash-safe log per trial as it goes (readable by
``palpate replay``) and estimates the modulus with the same trial core (:mod:`robot.trial`) as
``palpate sim``: the joint fit with its verdict (the paper's estimate beside it), or on a rigid
reference the compliance, which the session's later trials then use.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from palpate.calibration import calibrate, with_compliance
from palpate.config.bench import LoadedBench
from palpate.config.sample import UNKNOWN, AssumedConfig
from palpate.config.schema import MM, StackConfig
from palpate.estimation.beam.section import Section
from palpate.estimation.fits.compliance import ComplianceFit
from palpate.estimation.trial.estimate import EstimatorInputs, TrialEstimate, estimate_trial
from palpate.estimation.trial.inputs import belief_fields, probe_inputs
from palpate.lab.hardware import Hardware
from palpate.lab.plan import BenchTrial, plan_bench_trials
from palpate.live import Publisher, View
from palpate.robot.dynamixel.stats import BusStats
from palpate.robot.indentation import PLANNED_ENDS
from palpate.robot.plan import State
from palpate.robot.rig import ServoFbgRig
from palpate.robot.trial.outcome import Outcome, outcome_fields
from palpate.robot.trial.record import header_common
from palpate.robot.trial.run import TrialResult
from palpate.robot.trial.session import TrialSetup, run_session_trial
from palpate.robot.trial.setup import (
    position_tolerance,
    prober_for,
    rig_settings,
    sensor_section,
)

__all__ = [
    "PLANNED",
    "SKIPPED",
    "BenchOutcome",
    "BenchTrial",
    "Session",
    "plan_bench_trials",
    "run_bench_trial",
    "run_bench_trials",
]

SKIPPED = State.SKIPPED
PLANNED = frozenset(s.value for s in PLANNED_ENDS)  # trial ends that keep torque on


@dataclass
class BenchOutcome(Outcome):
    """A bench trial's outcome (``robot.trial.outcome.Outcome``) with the bench file's planned
    trial (its stated modulus in ``trial.modulus``) and the servo bus's counters."""

    trial: BenchTrial
    duration: float = 0.0
    bus: dict[str, object] | None = None  # the servo bus during the trial (BusStats, measured)

    def as_dict(self) -> dict[str, Any]:
        t = self.trial
        modulus = self.modulus()
        rel = None
        if modulus is not None and t.modulus is not None:
            rel = (modulus - t.modulus) / t.modulus
        return {
            **t.describe(),
            "state": self.state,
            "reason": self.reason,
            **self.estimate_row(),
            "reference_kpa": None if t.modulus is None else t.modulus / 1e3,
            "relative_error": rel,
            "duration_s": self.duration,
            "bus": self.bus,
            "log": self.log_path,
        }


def bus_stats(hw: Hardware) -> BusStats | None:
    """The servo bus's counters so far (a copy; None for a bus that keeps none)."""
    stats = getattr(hw.drive.bus, "stats", None)
    return stats.copy() if isinstance(stats, BusStats) else None


def _bus_during(
    before: BusStats | None, after: BusStats | None, missed: int
) -> dict[str, object] | None:
    """What the bus did during one trial (``BusStats.as_dict``; the worst latencies are the
    session's so far) and the ticks whose read was missed and tolerated (the rig's)."""
    if before is None or after is None:
        return None
    return {**after.since(before).as_dict(), "missed_reads": missed}


def run_bench_trials(
    hw: Hardware,
    trials: list[BenchTrial],
    loaded: LoadedBench,
    log_dir: Path,
    *,
    sync_to_clock: bool = False,
    progress: Callable[[BenchOutcome], None] | None = None,
    live: View | None = None,
    session: Session | None = None,
    stop: Callable[[], bool] | None = None,
) -> list[BenchOutcome]:
    """Run ``trials`` in order on opened hardware; one log per trial in ``log_dir``; each
    trial's ticks go to the ``live`` view when there is one (``palpate.live``).

    ``sync_to_clock`` is for emulators on a virtual clock (wait for each tick's frame); on
    hardware it stays False. With ``stop_on_fault`` a trial that does not complete ends the
    session: the rest are reported as skipped, torque is off. A trial on a rigid reference
    calibrates the compliance of its tube (the stage) for the session's later trials (and,
    with a ``session`` given, for what the caller runs after them). ``stop`` is asked every
    tick (True: the trial retracts and ends ``aborted``).
    """
    bench = loaded.bench
    outcomes: list[BenchOutcome] = []
    session = session if session is not None else Session(loaded.stack)
    torque_on = True  # DriveController.start() turned it on
    stopped = False
    for trial in trials:
        if stopped:
            why = "an earlier trial did not complete"
            outcomes.append(BenchOutcome(trial, state=SKIPPED, reason=why))
            continue
        if not torque_on:
            hw.drive.bus.set_torque(True)
            torque_on = True
        outcome, rig = run_bench_trial(
            hw,
            trial,
            loaded,
            session.stack,
            log_dir,
            sync_to_clock=sync_to_clock,
            live=live,
            stop=stop,
        )
        session.add(trial, outcome)
        outcomes.append(outcome)
        if progress is not None:
            progress(outcome)
        if outcome.state not in PLANNED:  # unreachable is an answer: torque on, the session goes on
            torque_on = False  # run_trial released the servos
            stopped = bench.stop_on_fault
        elif bench.after_trial == "release":
            rig.release()
            torque_on = False
    return outcomes


def run_bench_trial(
    hw: Hardware,
    trial: BenchTrial,
    loaded: LoadedBench,
    stack: StackConfig,
    log_dir: Path,
    *,
    sync_to_clock: bool = False,
    live: View | None = None,
    stop: Callable[[], bool] | None = None,
) -> tuple[BenchOutcome, ServoFbgRig]:
    """One trial on opened hardware with ``stack`` (the session's calibration), its log in
    ``log_dir`` and its ticks on the ``live`` view; ``stop`` asked every tick (True: retract,
    ``aborted``); the outcome (with what the bus did) and the rig (to release the servos)."""
    publisher = None if live is None else live.trial(trial.stage)
    before = bus_stats(hw)
    running = (sync_to_clock, publisher, stop)
    outcome, rig = _run_one(hw, trial, loaded, stack, log_dir, running)
    outcome.bus = _bus_during(before, bus_stats(hw), rig.missed_reads)
    return outcome, rig


class Session:
    """The robot configuration as a session calibrates it: the file's, with the compliances
    its rigid-reference trials found so far (``palpate.calibration``)."""

    def __init__(self, stack: StackConfig) -> None:
        self.base = stack
        self.stack = stack
        self.fits: list[tuple[str, ComplianceFit | None]] = []

    def add(self, trial: BenchTrial, outcome: BenchOutcome) -> None:
        if outcome.calibration is None:
            return
        self.fits.append((trial.stage.rig_key, outcome.calibration))
        self.stack = with_compliance(self.base, self.found)

    @property
    def found(self) -> dict[str, tuple[float, float]]:
        """The calibrated compliance (m/N) per rig key so far."""
        return calibrate(self.fits)


def bench_inputs(trial: BenchTrial, loaded: LoadedBench, stack: StackConfig) -> EstimatorInputs:
    """What the joint fit is told on the bench: the trial's belief (``assumed:``; thickness and
    bonding unknown unless stated), the tube's (stage's) calibrated compliance in ``stack``,
    the campaign's limits. The misalignment is not measured at a stored pose (0)."""
    c = loaded.bench.campaign
    stage = trial.stage
    compliance, calibrated = stack.compliance(None if stage.tube is None else stage.tube.name)
    belief = belief_fields(trial.assumed, thickness=UNKNOWN, bonded=UNKNOWN, poisson=trial.poisson)
    return EstimatorInputs(
        kind=trial.kind,
        exposed_length=trial.exposed_length,
        flush_translation=trial.tube.flush_translation,
        tip_radius=stack.sensor.tip_radius,
        encoder_resolution=position_tolerance(stack) / 1.5,
        misalignment=0.0,
        compliance=compliance,
        compliance_calibrated=calibrated,
        misalignment_tolerance=math.radians(c.misalignment_tolerance_deg),
        motion_tolerance=c.motion_tolerance,
        gated=c.gated,
        travel_window=c.max_travel_past_contact_mm * MM,
        designed_range=stack.sensor.designed_range,
        rigid=trial.rigid,
        **belief,
    )


def _run_one(
    hw: Hardware,
    trial: BenchTrial,
    loaded: LoadedBench,
    stack: StackConfig,
    log_dir: Path,
    running: tuple[bool, Publisher | None, Callable[[], bool] | None],
) -> tuple[BenchOutcome, ServoFbgRig]:
    """Zero the strains, run one trial with its log, estimate; the outcome and the rig.
    ``running``: whether to wait for each tick's frame on the clock, the live view's publisher,
    the operator's stop."""
    sync_to_clock, publisher, stop = running
    c = loaded.bench.campaign
    tick = 1.0 / loaded.bench.control_rate_hz
    settings = rig_settings(
        c, stack, tick, sync_to_clock=sync_to_clock, exposed_length=trial.exposed_length
    )
    rig = ServoFbgRig.for_stack(hw.drive, hw.reader, stack, hw.clock, settings)
    section = sensor_section(stack)
    inputs = bench_inputs(trial, loaded, stack)
    # the robot probes the surface first when the campaign says so (null: it does)
    radius = (trial.assumed or AssumedConfig()).surface_radius(None)

    def estimate(result: TrialResult) -> TrialEstimate:
        told = inputs  # and what probing measured, as the replay of its log is told
        if result.probe is not None:
            told = dataclasses.replace(inputs, **probe_inputs(result.probe.as_dict()))
        return estimate_trial(
            result,
            kind=trial.kind,
            exposed_length=trial.exposed_length,
            flush_translation=trial.tube.flush_translation,
            stack=stack,
            section=section,
            poisson=told.poisson,
            inputs=told,
        )

    setup = TrialSetup(
        trial.plan,
        c,
        stack,
        estimate=estimate,
        log_path=log_dir / f"{trial.trial_id}.jsonl",
        header=_header(trial, loaded, section, inputs),
        prober=None if trial.stage.tube is None else prober_for(c, stack, trial.tube, radius),
        on_tick=publisher,
        stop=stop,
    )
    done = run_session_trial(rig, hw.clock, setup)
    fields = outcome_fields(done.result, done.estimate, done.log_path)
    return BenchOutcome(trial, duration=done.result.duration, **fields), rig


def _header(
    trial: BenchTrial, loaded: LoadedBench, section: Section, inputs: EstimatorInputs
) -> dict[str, Any]:
    """The log header; the keys ``palpate replay`` reads are those of a simulated trial."""
    stack = loaded.stack
    tube = trial.stage.tube
    return {
        "trial": trial.trial_id,
        "source": "bench",
        "bench_file": str(loaded.path),
        "ports": {"servos": stack.servos.port, "board": stack.board.port},
        "spec": {
            "kind": trial.kind,
            "sample": trial.sample,
            "modulus": trial.modulus,
            "poisson": trial.poisson,
            "tube": trial.tube.name,
            "target": dataclasses.asdict(trial.target),
            "roll": trial.plan.roll,
            "exposed_length": trial.exposed_length,
            "rigid": trial.rigid,
        },
        **header_common(trial.plan, section, stack.sensor, tube, inputs.poisson, inputs),
    }
