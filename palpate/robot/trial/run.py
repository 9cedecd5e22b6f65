"""One indentation trial: the control loop that joins a rig, the state machine and the log.

The loop is the same on the bench, on the emulators over ptys and on the in-process fast path;
only the :class:`Rig` differs. Each control tick: read the rig (encoders, strains, contact event,
stream and servo health), step the :class:`~robot.indentation.IndentationMachine`, send its
command, log the tick, let one tick of time pass on the clock. Every record is flushed as it is
written, so a crash keeps the trial up to the crash.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any, Protocol

from ...estimation.detect.buckling import BucklingDetector
from ...sensor.clock import Clock
from ..indentation import (
    PLANNED_ENDS,
    Command,
    Guards,
    IndentationMachine,
    Observation,
    Prober,
    State,
    Transition,
    TrialMarks,
    TrialPlan,
)
from ..probe_result import ProbeResult
from ..records.log import TrialLogWriter


class Rig(Protocol):
    """What a trial needs from the hardware (or its emulation)."""

    @property
    def tick(self) -> float:
        """The control period (s): the loop lets this much time pass between ticks."""
        ...

    def observe(self, t: float) -> Observation:
        """Read encoders and the newest strains; never raises on a servo or stream fault
        (it reports them in the observation)."""
        ...

    def command(self, cmd: Command) -> None:
        """Send goals (advance, roll) with a speed limit; apply the torque flag."""
        ...

    def recover(self) -> bool:
        """Try to clear a servo fault (reboot the faulted servo) so the stage can retract."""
        ...

    def release(self) -> None:
        """Torque off on every servo. Must not raise."""
        ...


@dataclass
class TrialResult:
    state: State
    reason: str
    marks: TrialMarks
    ticks: int
    duration: float  # simulated or wall seconds on the rig's clock
    transitions: list[Transition] = field(default_factory=list)
    # (state after the tick, advance m, strains) per tick, as in the log's sample records: the
    # whole-record estimators (``estimation.trial.estimate``) read it without a log
    record: list[tuple[str, float, tuple[float, ...]]] = field(default_factory=list)
    times: list[float] = field(default_factory=list)  # each record row's time (s, the rig's clock)
    # each row's tip-grating load (N; NaN where the rig had none), empty without a tip grating
    tip_forces: list[float] = field(default_factory=list)
    beats: list[float] = field(default_factory=list)  # the ticks (s) with an ECG R-wave pulse
    probe: ProbeResult | None = None  # what probing found, when the trial probed
    # the stale stream's gaps the motion held through: (start s, duration s, state held)
    stream_gaps: list[tuple[float, float, str]] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return self.state is State.DONE

    @property
    def probing_time(self) -> float:
        """Seconds spent probing (0 without), from the transitions."""
        start = next((t.t for t in self.transitions if t.target is State.PROBING), None)
        end = next((t.t for t in self.transitions if t.source is State.PROBING), None)
        return 0.0 if start is None or end is None else end - start


def run_trial(
    rig: Rig,
    clock: Clock,
    plan: TrialPlan,
    guards: Guards,
    detector: BucklingDetector,
    log: TrialLogWriter | None = None,
    *,
    max_ticks: int = 200_000,
    on_tick: Callable[[Observation, State], None] | None = None,
    prober: Callable[[TrialPlan], Prober] | None = None,
    stop: Callable[[], bool] | None = None,
) -> TrialResult:
    """Run one trial to DONE, UNREACHABLE, FAULT or ABORTED; the rig is left retracted or
    torque-free. ``prober`` builds the probing step (``robot.probing``) when the trial probes;
    ``stop`` is asked before each tick whether an operator stop came (it retracts, ABORTED).

    One tick every ``rig.tick`` seconds of ``clock``; after ``max_ticks`` the trial is aborted
    (and retracts). Every transition and every tick is written to ``log`` as it happens, and
    what probing found as a ``probe`` record when it is found."""
    out = TrialResult(State.IDLE, "", TrialMarks(), 0, 0.0)  # filled as the trial runs

    def record_transition(tr: Transition) -> None:
        out.transitions.append(tr)
        if log is not None:
            log.write(_transition_record(tr))

    def record_gap(t: float, duration: float, state: State) -> None:
        _record_gap(out, log, (t, duration, state.value))

    machine = IndentationMachine(
        plan, guards, detector, on_transition=record_transition, on_gap=record_gap, prober=prober
    )
    t0 = clock.now()
    ticks, recovered, probe_logged = 0, False, False
    try:
        while not machine.finished:
            if _out_of_ticks(machine, clock.now(), ticks, max_ticks):
                break
            if stop is not None and machine.ending is not State.ABORTED and stop():
                machine.abort(clock.now(), "stop requested")
            obs, cmd, recovered = _tick(rig, machine, clock.now(), recovered)
            # a row whose strains are stale has no advance: no estimate reads it (as a missed read)
            advance = math.nan if machine.stream_held else obs.measured_advance
            _append_row(out, obs, machine.state, advance)
            if log is not None:
                probe_logged = _write_tick(log, obs, advance, machine, cmd, probe_logged)
            if on_tick is not None:
                on_tick(obs, machine.state)
            ticks += 1
            if not machine.finished:
                clock.sleep(rig.tick)
    except BaseException as exc:
        _crashed(exc, rig, machine.marks, log, ticks, clock, t0)
        raise
    if machine.state not in PLANNED_ENDS:
        rig.release()  # torque policy: a trial that did not complete leaves the servos limp
    out.state, out.reason, out.marks = machine.state, machine.marks.reason, machine.marks
    out.ticks, out.duration, out.probe = ticks, clock.now() - t0, machine.probe
    return out


def _record_gap(
    out: TrialResult, log: TrialLogWriter | None, gap: tuple[float, float, str]
) -> None:
    """A stale stream's gap the motion held through: in the result and as a log record."""
    out.stream_gaps.append(gap)
    if log is not None:
        log.write({"kind": "stream_gap", "t": gap[0], "duration": gap[1], "state": gap[2]})


def _append_row(out: TrialResult, obs: Observation, state: State, advance: float) -> None:
    """One tick's row: its state, advance and strains, its time, an R wave's tick, and its tip
    load (the rows before the first one NaN: the list stays row-aligned)."""
    out.record.append((state.value, advance, tuple(obs.strains)))
    out.times.append(obs.t)
    if obs.beat:
        out.beats.append(obs.t)
    if obs.tip_force is None and not out.tip_forces:
        return
    if not out.tip_forces:
        out.tip_forces.extend([math.nan] * (len(out.record) - 1))
    out.tip_forces.append(math.nan if obs.tip_force is None else obs.tip_force)


def _out_of_ticks(machine: IndentationMachine, t: float, ticks: int, max_ticks: int) -> bool:
    """Past ``max_ticks`` the trial is aborted (it retracts); True once even the retraction has
    had 100,000 ticks more: the loop stops."""
    if ticks >= max_ticks:
        machine.abort(t, f"tick budget of {max_ticks} exhausted")
        return ticks >= max_ticks + 100_000
    return False


def _write_tick(
    log: TrialLogWriter,
    obs: Observation,
    advance: float,
    machine: IndentationMachine,
    cmd: Command,
    probed: bool,
) -> bool:
    """The tick's sample record (``advance`` as the record keeps it), then what probing found
    once it is found; returns whether the probe record is written."""
    log.write(_sample_record(obs, advance, machine.state, cmd))
    if machine.probe is not None and not probed:
        log.write({"kind": "probe", **machine.probe.as_dict()})
        return True
    return probed


def _tick(
    rig: Rig, machine: IndentationMachine, t: float, recovered: bool
) -> tuple[Observation, Command, bool]:
    """Observe, step the machine, command; ``recovered``: the one recovery was tried."""
    obs = rig.observe(t)
    cmd = machine.step(obs)
    if obs.servo_fault is not None and machine.state is State.RETRACTING and not recovered:
        # One attempt to clear the fault (reboot) so the sensor can be pulled back; a fault
        # seen again while retracting ends the trial in FAULT with torque off.
        recovered = True
        rig.recover()
    rig.command(cmd)
    return obs, cmd, recovered


def _crashed(
    exc: BaseException,
    rig: Rig,
    marks: TrialMarks,
    log: TrialLogWriter | None,
    ticks: int,
    clock: Clock,
    t0: float,
) -> None:
    """An exception ended the loop: name it in the marks, release the servos, close the log's
    record with FAULT and the time since ``t0`` (the caller re-raises)."""
    marks.reason = f"crash: {type(exc).__name__}: {exc}"
    rig.release()
    if log is not None:
        crashed = TrialResult(State.FAULT, marks.reason, marks, ticks, clock.now() - t0)
        log.write(end_record(crashed))


def _sample_record(obs: Observation, advance: float, state: State, cmd: Command) -> dict[str, Any]:
    record = {
        "kind": "sample",
        "t": obs.t,
        "state": state.value,
        "advance": advance,
        "roll": obs.roll,
        "strains": list(obs.strains),
        "contact": obs.contact,
        "goal": cmd.advance,
    }
    if obs.tip_force is not None:
        record["tip_force"] = obs.tip_force
    if obs.beat:
        record["beat"] = True
    return record


def _transition_record(tr: Transition) -> dict[str, Any]:
    return {
        "kind": "transition",
        "t": tr.t,
        "from": tr.source.value,
        "to": tr.target.value,
        "reason": tr.reason,
        "advance": tr.advance,
        "strains": list(tr.strains),
    }


def end_record(result: TrialResult) -> dict[str, Any]:
    """The closing record of a trial log: final state, reason, marks, ticks and duration."""
    marks = asdict(result.marks)
    marks["strains_at_buckling"] = list(result.marks.strains_at_buckling)
    return {
        "kind": "end",
        "state": result.state.value,
        "reason": result.marks.reason,
        "marks": marks,
        "ticks": result.ticks,
        "duration": result.duration if math.isfinite(result.duration) else None,
    }
