"""Every way a bench trial can end leaves a complete log and a recording with its summary.

Sessions through ``run_session`` on the emulators' pseudo-terminals (the hardware code path), on
a virtual clock, recordings on (the bench's default). The stage powers up at the shipped home
pose, 0 mm: behind the tube's flush translation, so the record starts with rows whose sensor is
still inside the tube, which the recording must keep as such and never hand to the beam model
(it did, and every rehearsal ended "bad input: lengths must be > 0 m"). Endings: done, a fault,
unreachable, Ctrl-C and SIGTERM mid-trial (a SIGKILL: ``test_crash_log.py``).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from mcap.reader import make_reader  # type: ignore[import-untyped,unused-ignore]

from palpate.cli import main
from palpate.config.bench import load_bench
from palpate.lab.hardware import Terminated
from palpate.robot.records.log import read_log
from palpate.robot.records.recording import read_recording
from palpate.sim.clock import VirtualClock
from palpate.simulation.twin import SimulatedBench, surface_at
from tests.e2e.test_trial_cli import ONE, ROBOT_SCENE, bench_file, run_on

# the shipped home pose (0 mm, the tube's flush translation: no sensor out) and a quick stage
FROM_HOME = (
    "drive: {max_speed_mm_per_s: 20, max_accel_mm_per_s2: 200}\nservos: {timeout_ms: 2000}\n"
)


class StopAt(VirtualClock):
    """A virtual clock that raises ``exc`` once from the trial's sleep when it passes ``at``
    (s): Ctrl-C or SIGTERM arriving mid-trial."""

    def __init__(self, at: float, exc: BaseException) -> None:
        super().__init__()
        self.at, self.exc = at, exc

    def sleep(self, dt: float) -> None:
        super().sleep(dt)
        if self.now() >= self.at and self.exc is not None:
            exc, self.exc = self.exc, None  # type: ignore[assignment]
            raise exc


def session(tmp_path: Path, trials: str, clock: VirtualClock, extra: str = "") -> list[Path]:
    """Run the bench file's trials on the ptys; the logs written (whatever ended the run)."""
    loaded = load_bench(bench_file(tmp_path, trials, extra, robot=FROM_HOME))
    stack = loaded.stack
    surface = surface_at(stack.tube("bent30"), 0.0, 41e-3, stack.sensor.tip_radius)
    sim = SimulatedBench(
        stack, ROBOT_SCENE, sample="S8", surface=surface, tube="bent30", clock=clock, wire=True
    )
    with sim:
        run_on(sim, loaded, clock, tmp_path / "logs")
    return sorted((tmp_path / "logs").glob("*.jsonl"))


def closed(log_path: Path) -> tuple[str, list[float]]:
    """The log's final state; the recording's tip force per sample, after checking that the
    log is complete and the recording opens with MCAP's indexed reader (its summary)."""
    log = read_log(log_path)
    assert log.complete, log_path
    assert not log.problems
    mcap = log_path.with_suffix(".mcap")
    with open(mcap, "rb") as fh:
        summary = make_reader(fh).get_summary()
    assert summary is not None
    assert summary.statistics is not None
    assert summary.statistics.message_count > 0
    rec = read_recording(mcap)
    assert rec.complete
    samples = list(log.of_kind("sample"))
    assert rec.count("/joint_states") == len(samples)
    force = [m.wrench.force.z for _, m in rec.messages.get("/tip/wrench", [])]
    assert len(force) == len(samples)
    inside = [s["advance"] is not None and s["advance"] <= 0.0 for s in samples]
    assert any(inside)  # the record starts with the sensor in the tube ...
    assert all(math.isnan(f) for f, k in zip(force, inside, strict=True) if k)  # ... no load
    assert log.end is not None
    return str(log.end["state"]), force


@pytest.mark.slow
def test_a_done_trial_from_the_home_pose_closes_its_log_and_recording(tmp_path: Path) -> None:
    (path,) = session(tmp_path, ONE, VirtualClock())
    state, force = closed(path)
    assert state == "done"
    assert min(f for f in force if not math.isnan(f)) < -0.5  # the beam buckled (P_cr ~1.4 N)


@pytest.mark.slow
def test_a_faulted_trial_closes_its_log_and_recording(tmp_path: Path) -> None:
    trials = "  - {target: up, sample: S8}\n"  # nothing above the sensor: no contact
    (path,) = session(tmp_path, trials, VirtualClock(), "campaign: {probe: false}\n")
    assert closed(path)[0] == "fault"


@pytest.mark.slow
def test_an_unreachable_trial_closes_its_log_and_recording(tmp_path: Path) -> None:
    (path,) = session(tmp_path, "  - {target: up, sample: S8}\n", VirtualClock())
    assert closed(path)[0] == "unreachable"


@pytest.mark.slow
@pytest.mark.parametrize("exc", [KeyboardInterrupt(), Terminated("SIGTERM")], ids=repr)
def test_an_interrupted_trial_closes_its_log_and_recording(
    tmp_path: Path, exc: BaseException
) -> None:
    clock = StopAt(3.0, exc)  # mid-way: positioned, approaching the sample
    with pytest.raises(type(exc)):
        session(tmp_path, ONE, clock)
    (path,) = sorted((tmp_path / "logs").glob("*.jsonl"))
    state, _ = closed(path)
    assert state == "fault"
    assert read_log(path).end["reason"].startswith(f"crash: {type(exc).__name__}")  # type: ignore[index]


@pytest.mark.slow
def test_export_of_a_log_that_starts_in_the_tube_exits_0(tmp_path: Path) -> None:
    (path,) = session(tmp_path, ONE, VirtualClock())
    assert main(["export", str(path), "--out", str(tmp_path / "again")]) == 0
    with open(tmp_path / "again" / path.with_suffix(".mcap").name, "rb") as fh:
        assert make_reader(fh).get_summary() is not None


@pytest.mark.slow
def test_palpate_trial_exits_1_on_a_fault_and_prints_its_results(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The command on the emulators' ptys in real time (as ``palpate emulate`` serves them): a
    trial that faults is exit 1 with its row in the JSON (0 done: ``test_rehearsal.py``; 2 bad
    input: ``test_trial_cli.py``)."""
    path = bench_file(
        tmp_path, "  - {target: up, sample: S8}\n", "campaign: {probe: false}\n", robot=FROM_HOME
    )
    loaded = load_bench(path)
    stack = loaded.stack
    surface = surface_at(stack.tube("bent30"), 0.0, 41e-3, stack.sensor.tip_radius)
    with SimulatedBench(stack, ROBOT_SCENE, sample="S8", surface=surface, tube="bent30") as sim:
        argv = ["trial", "--config", str(path), "--json"]
        code = main([*argv, "--servo-port", sim.servo_port, "--board-port", sim.board_port])
    assert code == 1
    (trial,) = json.loads(capsys.readouterr().out)["trials"]
    assert trial["state"] == "fault"
    assert trial["reason"].startswith("no contact within")
    assert trial["bus"]["transactions"] > 0
    closed(Path(trial["log"]))
