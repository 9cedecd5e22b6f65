"""The fault campaign: inject each fault of a scene into simulated trials, then check from the
emulators and the logs (never from what the controller believes) that every trial stopped
safely and kept its data.

Definitions (checked per trial by :func:`judge`):

**Safe stop** — all of:

1. the trial returned a final state (done, fault or aborted): nothing raised out of it;
2. the fiber's true strain (the world's, noise-free) never exceeded the strain limit;
3. the true advance past first touch never exceeded the travel guard plus ``TRAVEL_SLACK``;
4. at the end every servo is still (zero velocity) and either torque-free or holding within
   one encoder tick of its goal (so nothing moves on after the trial);
5. the sensor is off the tissue at the end (true advance past contact <= 0, zero force), unless
   retraction was impossible (the translation servo stalled, shut down or not answering at the
   end), in which case its torque must be off.

For a killed process (SIGKILL, nothing can run after it), 4-5 become: the translation servo's
last goal is within ``KILL_STOP_SLACK`` of where it is, so a servo left holding its goal stops
there; the emulator's state is written by the child just before it kills itself.

**Data kept** — all of: the log reads back with no bad line; it has its end record with the
same final state and reason the trial returned, and a non-empty reason; it holds one sample
record per control tick; and ``palpate replay`` reproduces the trial's estimate exactly from it.
For a killed process: every record written (flushed) before the kill reads back, there is no end
record, and replay reports the log as truncated.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import pickle
import signal
import subprocess
import sys
import tempfile
from collections import Counter
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from config.faults import FaultCase
from config.loader import ConfigError, from_mapping
from config.scene import SceneConfig
from config.schema import ServoBusConfig, StackConfig
from palpate.campaign import campaign_trials
from palpate.commands.replay import replay
from palpate.preflight import check_campaign, check_reachable
from palpate.simtrial import TrialOutcome, TrialSpec, run_sim_trial
from robot.trial.log import TrialLogWriter, read_log
from sim.board import BoardEmulator, BoardFaults
from sim.clock import VirtualClock
from sim.dynamixel.bus import EmulatedBus
from sim.dynamixel.faults import FaultyBus, PacketFaults
from sim.world import Surface, World
from wire import dynamixel as tables

TRAVEL_SLACK = 0.1e-3  # m past the travel guard: a tick or two at approach speed, tracking lag
KILL_STOP_SLACK = 0.1e-3  # m a held servo may still travel toward its last goal after a kill
HARDWARE_ERROR_BITS: dict[str, int] = {
    "input_voltage": tables.HW_INPUT_VOLTAGE,
    "overheating": tables.HW_OVERHEATING,
    "encoder": tables.HW_ENCODER,
    "electrical_shock": tables.HW_ELECTRICAL_SHOCK,
    "overload": tables.HW_OVERLOAD,
}
_SERVO_FIELDS = ("outer_roll", "inner_roll", "translation")


def servo_id(cfg: ServoBusConfig, name: str) -> int:
    return int(getattr(cfg, name).id)


def board_faults_of(case: FaultCase, source: str, index: int) -> BoardFaults | None:
    """The case's board faults, validated; a bad key raises ConfigError naming file and key."""
    if case.board is None:
        return None
    return from_mapping(BoardFaults, case.board, source, f"faults.cases[{index}].board")


def check_fault_scene(scene: SceneConfig, source: str) -> None:
    """Validate what the scene loader cannot (board fault keys live in ``sim``)."""
    if not scene.faults.cases:
        raise ConfigError(source, "faults.cases", "a fault campaign needs at least one case")
    for i, case in enumerate(scene.faults.cases):
        board_faults_of(case, source, i)


# -- ground truth and injection --------------------------------------------------------------


@dataclass
class ServoSnapshot:
    torque: bool
    velocity: float  # ticks/s
    remaining_ticks: int  # |goal - present|
    hardware_error: int


@dataclass
class GroundTruth:
    """What the emulators saw, independent of the controller."""

    fired_at: float | None = None
    contact_at: float | None = None
    max_strain: float = 0.0
    max_past_contact: float = -math.inf
    end_past_contact: float = -math.inf
    end_force: float = 0.0
    servos: dict[str, ServoSnapshot] = field(default_factory=dict)
    translation_blocked: str = ""  # why the stage could not move at the end, if it could not
    link: dict[str, int] = field(default_factory=dict)
    board: dict[str, Any] = field(default_factory=dict)
    records_written: int | None = None  # log lines flushed before a kill


def _snapshot(bus: EmulatedBus, cfg: ServoBusConfig) -> dict[str, ServoSnapshot]:
    out = {}
    for name in _SERVO_FIELDS:
        s = bus.servo(servo_id(cfg, name))
        out[name] = ServoSnapshot(
            torque=s.torque_enabled,
            velocity=s.velocity_ticks_per_s,
            remaining_ticks=abs(s.item("Goal_Position") - s.position_ticks),
            hardware_error=s.hardware_error,
        )
    return out


class FaultInjector:
    """Satisfies ``palpate.simtrial.EmulatorHook``: schedules one case's faults on the virtual
    clock and records the ground truth the checks use."""

    def __init__(
        self,
        case: FaultCase,
        servos: ServoBusConfig,
        *,
        seed: int,
        board_faults: BoardFaults | None = None,
        blackbox: Path | None = None,
        ready_after_records: int | None = None,
        ready_fd: int | None = None,
    ) -> None:
        self.case = case
        self.cfg = servos
        self.seed = seed
        self._board_faults = board_faults
        self.blackbox = blackbox
        self.ready_after_records = ready_after_records
        self.ready_fd = ready_fd
        self.truth = GroundTruth()
        self._trigger_at: float | None = None
        self._attached = False
        self._bus: FaultyBus | None = None
        self._board: BoardEmulator | None = None
        self._world: World | None = None
        self._clock: VirtualClock | None = None
        self._log: TrialLogWriter | None = None
        self._muted_until = -math.inf

    # -- EmulatorHook ---------------------------------------------------------------------------
    @property
    def board_faults(self) -> BoardFaults | None:
        return self._board_faults

    def make_bus(self, cfg: ServoBusConfig, clock: VirtualClock) -> EmulatedBus:
        self._bus = FaultyBus.from_config(cfg, clock=clock)
        return self._bus

    def attach(
        self, clock: VirtualClock, bus: EmulatedBus, board: BoardEmulator, world: World
    ) -> None:
        self._clock, self._board, self._world = clock, board, world
        early = self.case.early_contact_mm * 1e-3
        if early:  # the tissue is closer than the plan expects
            s = world.surface
            world.surface = Surface(point=s.point + early * s.normal, normal=s.normal)
        self._attached = True
        if self.case.trigger == "start":
            self._trigger_at = clock.now() + self.case.delay_s
        clock.on_advance(self._on_advance)

    def log_opened(self, log: TrialLogWriter) -> None:
        self._log = log

    def detach(self) -> None:
        """Final ground truth, after the control stack closed its ports."""
        self._attached = False
        if self._bus is None or self._world is None or self._clock is None:
            return
        t = self._clock.now()
        st = self._world.state(t)
        self.truth.end_past_contact = st.past_contact
        self.truth.end_force = st.P
        self.truth.servos = _snapshot(self._bus, self.cfg)
        self.truth.translation_blocked = self._blocked(t)
        self.truth.link = dataclasses.asdict(self._bus.link_stats)
        if self._board is not None:
            stats = dataclasses.asdict(self._board.stats)
            stats.pop("log", None)
            self.truth.board = stats

    # -- the schedule --------------------------------------------------------------------------
    def _on_advance(self, t: float) -> None:
        if not self._attached or self._world is None:
            return
        st = self._world.state(t)
        tr = self.truth
        tr.max_strain = max(tr.max_strain, max((abs(x) for x in st.strains), default=0.0))
        tr.max_past_contact = max(tr.max_past_contact, st.past_contact)
        if tr.contact_at is None and st.past_contact > 0.0:
            tr.contact_at = t
            if self.case.trigger == "contact":
                self._trigger_at = t + self.case.delay_s
        if tr.fired_at is None and self._trigger_at is not None and t >= self._trigger_at:
            tr.fired_at = t
            self._fire(t)
        log = self._log
        ready = self.ready_after_records
        fd = self.ready_fd
        if ready is not None and log is not None and fd is not None and log.records >= ready:
            os.write(fd, b"R")
            self.ready_fd = None

    def _fire(self, t: float) -> None:
        c = self.case
        bus = self._bus
        assert bus is not None  # make_bus ran before attach
        sid = servo_id(self.cfg, c.servo)
        servo = bus.servo(sid)
        if c.servo_timeout_s is not None:
            self._muted_until = t + c.servo_timeout_s
            bus.mute(sid, self._muted_until)
        if c.corrupt_replies:
            servo.corrupt_replies(c.corrupt_replies)
        if c.packet_loss or c.corrupt_probability:
            bus.set_packet_faults(PacketFaults(c.packet_loss, c.corrupt_probability), self.seed)
        bits = 0
        for name in c.hardware_error:
            bits |= HARDWARE_ERROR_BITS[name]
        if bits:
            servo.raise_hardware_error(bits)
        if c.stall:
            servo.set_stalled(True)
        if c.stream_stops and self._board is not None:
            self._board.disconnect()
        if c.kill:
            self._die(t)

    def _blocked(self, t: float) -> str:
        """Why the translation stage cannot move now, from the emulator ('' if it can)."""
        c = self.case
        assert self._bus is not None
        s = self._bus.servo(servo_id(self.cfg, "translation"))
        if c.stall and c.servo == "translation":
            return "stalled"
        if s.hardware_error & s.item("Shutdown"):
            return "shut down by a hardware error"
        if c.servo == "translation" and t < self._muted_until:
            return "not answering"
        return ""

    def _die(self, t: float) -> None:
        """SIGKILL this process, first writing what the emulators know (the black box)."""
        assert self._bus is not None
        assert self._world is not None
        if self.blackbox is not None:
            tr = self.truth
            box = {
                "t": t,
                "records_written": None if self._log is None else self._log.records,
                "max_strain": tr.max_strain,
                "max_past_contact": tr.max_past_contact,
                "servos": {
                    k: dataclasses.asdict(v) for k, v in _snapshot(self._bus, self.cfg).items()
                },
            }
            self.blackbox.write_text(json.dumps(box), encoding="utf-8")
        os.kill(os.getpid(), signal.SIGKILL)


# -- one trial -------------------------------------------------------------------------------


@dataclass
class FaultTrialResult:
    case: str
    trial: str
    state: str
    reason: str
    safe: bool
    data_kept: bool
    problems: list[str]
    log: str | None
    truth: GroundTruth

    def as_dict(self) -> dict[str, Any]:
        d = dataclasses.asdict(self)
        d["truth"] = {k: v for k, v in d["truth"].items() if k != "servos"}
        return d


@dataclass(frozen=True)
class FaultJob:
    case: FaultCase
    board: BoardFaults | None
    spec: TrialSpec
    scene: SceneConfig
    stack: StackConfig
    log_dir: Path
    transport: str = "fast"


def _scene_for(case: FaultCase, scene: SceneConfig) -> SceneConfig:
    if case.tube_tip_stiffness_n_per_mm is None:
        return scene
    fid = dataclasses.replace(
        scene.fidelity, tube_tip_stiffness_n_per_mm=case.tube_tip_stiffness_n_per_mm
    )
    return dataclasses.replace(scene, fidelity=fid)


def _injector(job: FaultJob, **kwargs: Any) -> FaultInjector:
    board = job.board
    if board is not None:
        board = dataclasses.replace(board, seed=board.seed + job.spec.seed)
    return FaultInjector(
        job.case, job.stack.servos, seed=job.spec.seed, board_faults=board, **kwargs
    )


def run_fault_trial(job: FaultJob) -> FaultTrialResult:
    """Run one trial under one fault case and judge it. Never raises for a trial's failure."""
    if job.case.kill:
        return _run_killed(job)
    inj = _injector(job)
    outcome: TrialOutcome | None = None
    crash = ""
    try:
        outcome = run_sim_trial(
            job.spec,
            _scene_for(job.case, job.scene),
            job.stack,
            transport="wire" if job.transport == "wire" else "fast",
            log_dir=job.log_dir,
            hook=inj,
        )
    except Exception as exc:  # the campaign reports it: "nothing raises" is what it checks
        crash = f"raised {type(exc).__name__}: {exc}"
    return judge(job, outcome, inj.truth, crash)


def judge(
    job: FaultJob, outcome: TrialOutcome | None, truth: GroundTruth, crash: str = ""
) -> FaultTrialResult:
    """Apply the safe-stop and data-kept definitions of this module's docstring."""
    problems: list[str] = []
    safe = _truth_within_limits(job, truth, problems)
    if outcome is None:
        problems.append(crash or "no outcome")
        log_path = job.log_dir / f"{job.spec.trial_id}.jsonl"
        return FaultTrialResult(
            job.case.name, job.spec.trial_id, "crash", crash, False, False, problems,
            str(log_path) if log_path.exists() else None, truth,
        )  # fmt: skip
    if outcome.state not in ("done", "fault", "aborted"):
        safe = _fail(problems, f"final state {outcome.state!r}")
    for name, s in truth.servos.items():
        if s.velocity != 0.0:
            safe = _fail(problems, f"{name} still moving at {s.velocity:.0f} ticks/s")
        if s.torque and s.remaining_ticks > 1:
            safe = _fail(problems, f"{name} holds torque {s.remaining_ticks} ticks off its goal")
    touching = truth.end_past_contact > 0.0 or truth.end_force > 0.0
    if touching:
        blocked = truth.translation_blocked
        torque = truth.servos["translation"].torque if truth.servos else True
        if not blocked:
            safe = _fail(
                problems, f"not retracted: {truth.end_past_contact * 1e3:.3f} mm past contact"
            )
        elif torque:
            safe = _fail(problems, f"translation {blocked} and still torqued against the tissue")
    kept = _data_kept(outcome, problems)
    return FaultTrialResult(
        job.case.name,
        job.spec.trial_id,
        outcome.state,
        outcome.reason,
        safe,
        kept,
        problems,
        outcome.log_path,
        truth,
    )


def _fail(problems: list[str], text: str) -> bool:
    problems.append(text)
    return False


def _truth_within_limits(job: FaultJob, truth: GroundTruth, problems: list[str]) -> bool:
    ok = True
    limit = job.stack.fbg.strain_limit
    if truth.max_strain > limit:
        ok = _fail(problems, f"true strain {truth.max_strain * 1e6:.0f} ue over the limit")
    travel = job.scene.campaign.max_travel_past_contact_mm * 1e-3 + TRAVEL_SLACK
    if truth.max_past_contact > travel:
        ok = _fail(problems, f"true travel past contact {truth.max_past_contact * 1e3:.3f} mm")
    return ok


def _data_kept(outcome: TrialOutcome, problems: list[str]) -> bool:
    if outcome.log_path is None:
        return _fail(problems, "no log")
    path = Path(outcome.log_path)
    log = read_log(path)
    ok = True
    if log.bad_lines:
        ok = _fail(problems, f"{log.bad_lines} unreadable log lines")
    end = log.end
    if end is None:
        return _fail(problems, "log has no end record")
    if end.get("state") != outcome.state or end.get("reason") != outcome.reason:
        ok = _fail(problems, f"log ends {end.get('state')}/{end.get('reason')!r}")
    if not end.get("reason"):
        ok = _fail(problems, "log does not say why the trial ended")
    samples = sum(1 for _ in log.of_kind("sample"))
    if samples != outcome.ticks:
        ok = _fail(problems, f"{samples} sample records for {outcome.ticks} ticks")
    if not replay(path).get("identical"):
        ok = _fail(problems, "replay does not reproduce the estimate")
    return ok


# -- the killed process ----------------------------------------------------------------------


def child_command(job: FaultJob, blackbox: Path, ready_after_records: int | None = None) -> Any:
    """argv and the pickled job file for a child that runs ``job`` (and may kill itself)."""
    fd, name = tempfile.mkstemp(prefix="palpate-fault-", suffix=".pkl")
    with os.fdopen(fd, "wb") as fh:
        pickle.dump((job, str(blackbox), ready_after_records), fh)
    return [sys.executable, "-m", "palpate.faults", name], Path(name)


def child_main(job_file: str) -> int:
    """Entry of the child process: run the job's trial; report readiness on stdout (fd 1)."""
    with open(job_file, "rb") as fh:
        job, blackbox, ready_after = pickle.load(fh)
    inj = _injector(
        job,
        blackbox=Path(blackbox),
        ready_after_records=ready_after,
        ready_fd=1 if ready_after is not None else None,
    )
    run_sim_trial(
        job.spec, _scene_for(job.case, job.scene), job.stack, log_dir=job.log_dir, hook=inj
    )
    return 0


def _run_killed(job: FaultJob) -> FaultTrialResult:
    log_path = job.log_dir / f"{job.spec.trial_id}.jsonl"
    blackbox = job.log_dir / f"{job.spec.trial_id}.blackbox.json"
    argv, job_file = child_command(job, blackbox)
    try:
        proc = subprocess.run(argv, capture_output=True, check=False, timeout=600)
    finally:
        job_file.unlink(missing_ok=True)
    truth = GroundTruth()
    problems: list[str] = []
    if proc.returncode != -signal.SIGKILL:
        err = proc.stderr.decode(errors="replace").strip().splitlines()[-1:] or [""]
        problems.append(f"child exited with {proc.returncode}, not killed: {err[0]}")
        return FaultTrialResult(
            job.case.name, job.spec.trial_id, "not killed", "", False, False, problems,
            str(log_path), truth,
        )  # fmt: skip
    return judge_killed(job, log_path, blackbox, problems)


def judge_killed(
    job: FaultJob, log_path: Path, blackbox: Path, problems: list[str]
) -> FaultTrialResult:
    """Safe stop and data kept for a trial whose process was SIGKILLed (module docstring)."""
    truth = GroundTruth()
    box = json.loads(blackbox.read_text(encoding="utf-8"))
    truth.fired_at = box["t"]
    truth.max_strain = box["max_strain"]
    truth.max_past_contact = box["max_past_contact"]
    truth.records_written = box["records_written"]
    safe = _truth_within_limits(job, truth, problems)
    lead = job.stack.drive.lead
    remaining = box["servos"]["translation"]["remaining_ticks"] * lead / tables.TICKS_PER_REV
    if remaining > KILL_STOP_SLACK:
        safe = _fail(problems, f"the stage would still travel {remaining * 1e3:.3f} mm")
    kept = True
    log = read_log(log_path)
    read_back = 1 + len(log.records)  # header included, as the writer counts
    if log.bad_lines:
        kept = _fail(problems, f"{log.bad_lines} unreadable log lines")
    if read_back != truth.records_written:
        kept = _fail(problems, f"{read_back} records read back, {truth.records_written} written")
    if log.complete:
        kept = _fail(problems, "a killed trial's log has an end record")
    if "truncated" not in str(replay(log_path).get("message", "")):
        kept = _fail(problems, "replay does not report the truncated log")
    return FaultTrialResult(
        job.case.name, job.spec.trial_id, "killed", "SIGKILL", safe, kept, problems,
        str(log_path), truth,
    )  # fmt: skip


# -- the campaign ----------------------------------------------------------------------------


def fault_jobs(
    scene: SceneConfig, stack: StackConfig, source: str, seed: int, log_dir: Path, transport: str
) -> list[FaultJob]:
    """``trials_per_case`` trials of the scene's campaign under each case (fixed order)."""
    check_fault_scene(scene, source)
    specs = campaign_trials(scene, stack, seed)
    if not specs:
        raise ValueError(f"{source}: the campaign has no trials")
    jobs = []
    n = scene.faults.trials_per_case
    for i, case in enumerate(scene.faults.cases):
        board = board_faults_of(case, source, i)
        for j in range(n):
            base = specs[j % len(specs)]
            spec = dataclasses.replace(
                base,
                trial_id=f"{case.name}-{base.trial_id}-{j}",
                seed=base.seed + 7919 * (i + 1) + j,
            )
            jobs.append(FaultJob(case, board, spec, scene, stack, log_dir, transport))
    return jobs


def run_fault_campaign(
    jobs: Sequence[FaultJob],
    *,
    workers: int = 1,
    progress: Callable[[FaultTrialResult], None] | None = None,
) -> list[FaultTrialResult]:
    """Run the jobs (in parallel with ``workers`` > 1); results keep the jobs' order."""
    results: list[FaultTrialResult] = []
    if workers <= 1:
        for job in jobs:
            results.append(run_fault_trial(job))
            if progress is not None:
                progress(results[-1])
        return results
    with ProcessPoolExecutor(max_workers=workers) as pool:
        for res in pool.map(run_fault_trial, jobs):
            results.append(res)
            if progress is not None:
                progress(res)
    return results


@dataclass(frozen=True)
class FaultRow:
    fault: str
    trials: int
    safe_stops: int
    data_kept: int
    outcome: str  # the most common final state and reason


def fault_table(results: Sequence[FaultTrialResult]) -> list[FaultRow]:
    rows: list[FaultRow] = []
    order = list(dict.fromkeys(r.case for r in results))
    for name in order:
        rs = [r for r in results if r.case == name]
        outcomes = [f"{r.state}: {r.reason}" for r in rs]
        common = Counter(outcomes).most_common(1)[0][0]  # ties: the first seen
        rows.append(
            FaultRow(
                name,
                len(rs),
                sum(r.safe for r in rs),
                sum(r.data_kept for r in rs),
                common,
            )
        )
    return rows


def run_command(args: Any) -> int:
    """``palpate sim --faults``: exit 0 when every trial stopped safely and kept its data."""
    from config import load, load_stack, resolve

    scene_path = args.scene if args.scene else resolve("scenes/faults.yaml")
    scene = load(SceneConfig, scene_path)
    stack = load_stack(resolve(scene.robot))
    robot_source = str(resolve(scene.robot))
    check_campaign(scene, stack, str(scene_path), robot_source)
    out_dir: Path = args.out / scene.name
    log_dir = out_dir / "logs"
    transport = "wire" if args.wire else scene.transport
    jobs = fault_jobs(scene, stack, str(scene_path), args.seed, log_dir, transport)
    if args.limit:
        jobs = jobs[: args.limit]
    check_reachable([j.spec for j in jobs], stack, str(scene_path), robot_source)
    log_dir.mkdir(parents=True, exist_ok=True)
    for old in (*log_dir.glob("*.jsonl"), *log_dir.glob("*.blackbox.json")):
        old.unlink()

    def progress(r: FaultTrialResult) -> None:
        if not args.json:
            mark = "ok" if r.safe and r.data_kept else "FAILED"
            print(f"  {r.trial}: {mark}: {r.state}: {r.reason}", file=sys.stderr, flush=True)

    results = run_fault_campaign(jobs, workers=max(1, args.workers), progress=progress)
    rows = fault_table(results)
    if args.json:
        payload = {
            "scene": scene.name,
            "transport": transport,
            "seed": args.seed,
            "faults": [dataclasses.asdict(r) for r in rows],
            "trials": [r.as_dict() for r in results],
        }
        print(json.dumps(payload, indent=2, default=_json_default))
    else:
        print(render_table(rows))
        for r in results:
            if r.problems:
                print(f"  {r.trial}: {'; '.join(r.problems)}")
        print(f"logs: {log_dir}")
    ok = all(r.safe and r.data_kept for r in results)
    return 0 if ok else 1


def _json_default(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return str(value)


def render_table(rows: Sequence[FaultRow]) -> str:
    """The fault table as text: fault, trials, safe stops, data kept, most common outcome."""
    head = f"{'fault':<24} {'trials':>6} {'safe stops':>10} {'data kept':>9}  outcome"
    lines = [head, "-" * len(head)]
    for r in rows:
        outcome = r.outcome if len(r.outcome) <= 70 else r.outcome[:67] + "..."
        lines.append(f"{r.fault:<24} {r.trials:>6} {r.safe_stops:>10} {r.data_kept:>9}  {outcome}")
    return "\n".join(lines)


if __name__ == "__main__":
    sys.exit(child_main(sys.argv[1]))
