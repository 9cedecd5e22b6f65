"""``palpate trial`` on the bench path: the bench file, the plan, clean failures without hardware,
and whole sessions on the emulators' pseudo-terminals (the hardware code path) on a virtual clock.

Tests marked ``hardware`` talk to a real bench; they run only when PALPATE_HW_SERVO_PORT and
PALPATE_HW_BOARD_PORT name its ports, and never move the stage.
"""

from __future__ import annotations

import dataclasses
import errno
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest
import serial

from palpate.cli import main
from palpate.config import load, resolve
from palpate.config.bench import LoadedBench, load_bench
from palpate.config.loader import ConfigError
from palpate.config.scene import SceneConfig
from palpate.lab.hardware import HardwareError, explain, open_hardware
from palpate.lab.trial import SKIPPED, BenchOutcome, plan_bench_trials
from palpate.reports.replay import replay
from palpate.robot.motors import ServoTransportError
from palpate.robot.records.log import read_log
from palpate.services.lab import run_session
from palpate.sim.clock import VirtualClock
from palpate.simulation.twin import SimulatedBench, stations_for, surface_at

ROBOT_SCENE = load(SceneConfig, resolve("scenes/robot.yaml"))
# A quick stage, powered up 2 mm behind the stand-off pose, so a trial takes ~3 s simulated; a
# generous servo reply timeout (the emulator answers from a thread a busy machine may not run
# for a while: lateness is not a fault here, the trial runs on a virtual clock).
ROBOT_YAML = (
    "drive: {max_speed_mm_per_s: 20, max_accel_mm_per_s2: 200, home_translation_mm: 38}\n"
    "servos: {timeout_ms: 2000}\n"
)
TARGETS_YAML = """targets:
  - {name: down, tube: bent30, roll_deg: 0, translation_mm: 40}
  - {name: up, tube: bent30, roll_deg: 180, translation_mm: 40}
"""


def bench_file(tmp_path: Path, trials: str, extra: str = "", robot: str = ROBOT_YAML) -> Path:
    (tmp_path / "robot.yaml").write_text(robot, encoding="utf-8")
    (tmp_path / "targets.yaml").write_text(TARGETS_YAML, encoding="utf-8")
    path = tmp_path / "bench.yaml"
    path.write_text(
        f"servos: {{port: {tmp_path}/ttyNOPE0}}\n"
        f"board: {{port: {tmp_path}/ttyNOPE1}}\n"
        f"robot: {tmp_path}/robot.yaml\n"
        f"targets: {tmp_path}/targets.yaml\n"
        f"log_dir: {tmp_path}/logs\n"
        f"{extra}"
        f"trials:\n{trials}",
        encoding="utf-8",
    )
    return path


ONE = "  - {target: down, sample: S8, modulus_kpa: 314.53}\n"


def simulated(loaded: LoadedBench, clock: VirtualClock) -> SimulatedBench:
    """Both emulators on ptys, with S8 placed where target ``down`` expects it (1 mm on)."""
    stack = loaded.stack
    surface = surface_at(stack.tube("bent30"), 0.0, 41e-3, stack.sensor.tip_radius)
    return SimulatedBench(
        stack, ROBOT_SCENE, sample="S8", surface=surface, tube="bent30", clock=clock, wire=True
    )


def run_on(
    sim: SimulatedBench,
    loaded: LoadedBench,
    clock: VirtualClock,
    log_dir: Path,
    live: int | None = None,
) -> list[BenchOutcome]:
    """Every trial of the bench file through ``run_session`` on the simulated bench's ports
    (``live``: the live view's port, ``--live``)."""
    return run_session(
        loaded,
        plan_bench_trials(loaded),
        log_dir,
        servo_port=sim.servo_port,
        board_port=sim.board_port,
        clock=clock,
        sync_to_clock=True,
        live=live,
    )


def session_on_ptys(
    tmp_path: Path, trials: str, extra: str = ""
) -> tuple[list[BenchOutcome], list[bool], int]:
    """Run a bench file's trials through ``run_session`` on the emulators' ptys; return the
    outcomes, each servo's torque and the stage encoder after the session closed the bus."""
    loaded = load_bench(bench_file(tmp_path, trials, extra))
    clock = VirtualClock()
    with simulated(loaded, clock) as sim:
        outcomes = run_on(sim, loaded, clock, tmp_path / "logs")
        torque = [s.torque_enabled for s in sim.bus.servos]
        return outcomes, torque, sim.servo("translation").position_ticks


@pytest.mark.slow
def test_a_session_on_the_emulators_ptys_runs_logs_and_releases(tmp_path: Path) -> None:
    outcomes, torque, ticks = session_on_ptys(tmp_path, ONE)
    assert torque == [False, False, False]  # the bus closed with torque off
    # back at the retract pose (the power-up pose here), within the 5 um position tolerance
    # (one 4.9 um encoder tick): where in it the stage stops depends on the trial's motion
    assert abs(ticks) <= 1
    (o,) = outcomes
    assert o.state == "done", o.reason
    assert o.estimate is not None
    assert o.estimate.modulus is not None  # the paper's estimate: E ~ delta^-1.5 from the
    assert o.estimate.delta > 0  # FBG contact event, so only its presence is asserted here
    # the joint fit does not read the contact event: it is the estimate to hold to the truth
    assert o.joint is not None
    assert o.joint.modulus is not None
    assert abs(o.joint.modulus / 314.53e3 - 1.0) < 0.1
    log = read_log(Path(str(o.log_path)))
    assert log.complete
    assert log.header["source"] == "bench"
    assert [r["to"] for r in log.of_kind("transition")][-1] == "done"
    report = replay(Path(str(o.log_path)))
    assert report["identical"] is True
    assert report["paper_modulus"] == o.estimate.modulus
    # the joint fit, its interval and its verdict are logged and replayed as they were
    assert o.joint is not None
    assert o.joint.ci_low is not None
    assert o.joint.ci_high is not None
    assert o.joint.ci_low < o.joint.modulus < o.joint.ci_high  # type: ignore[operator]
    assert o.verdict is not None
    (estimate,) = log.of_kind("estimate")
    assert estimate["joint"]["ci_low"] == o.joint.ci_low
    assert estimate["verdict"] == o.verdict.as_dict()
    assert report["joint"] == estimate["joint"]
    assert report["replayed_verdict"] == estimate["verdict"]
    assert log.header["estimator"]["version"] == 2
    # on the bench thickness and bonding are unknown unless stated, and this robot file has
    # no calibrated compliance: all three are profiled, and the verdict says so
    assert set(o.joint.profiled) == {"thickness", "bonded", "compliance"}
    assert o.status == "suspect"
    assert any("not calibrated" in r for r in o.verdict.reasons)


COMPLIANT = """name: rehearsal
samples:
  - {name: REF, modulus_kpa: 1000000, rigid: true}
  - {name: S8, modulus_kpa: 314.53, assumed: {thickness_mm: 10, bonded: true}}
fidelity: {fbg_noise_pm: 1.0, imperfection_w0_over_l: 0.002, tube_tip_stiffness_n_per_mm: 10}
"""
REHEARSAL = (
    "  - {target: up, sample: REF, rigid: true}\n"
    "  - {target: down, sample: S8, modulus_kpa: 314.53,"
    " assumed: {thickness_mm: 10, bonded: true}}\n"
)


@pytest.mark.slow
def test_a_session_with_the_live_view_runs_as_without_it(tmp_path: Path) -> None:
    """``palpate trial --live``'s path: the view serves on a free port while the session runs
    (nobody connects: the publisher does no work) and the trial ends as it would without."""
    loaded = load_bench(bench_file(tmp_path, ONE))
    clock = VirtualClock()
    with simulated(loaded, clock) as sim:
        (o,) = run_on(sim, loaded, clock, tmp_path / "logs", live=0)
    assert o.state == "done", o.reason
    assert o.joint is not None
    assert o.joint.modulus is not None


@pytest.mark.slow
def test_a_hold_on_the_ptys_is_logged_fitted_and_replayed(tmp_path: Path) -> None:
    """The bench file's hold (issue 27) over the hardware path: the stage stands still after
    buckling, every held tick is logged, the relaxation fit reads an elastic sample as such,
    and the log replays to the same numbers."""
    outcomes, _, _ = session_on_ptys(tmp_path, ONE, "campaign: {hold_s: 1.0}\n")
    (o,) = outcomes
    assert o.state == "done", o.reason
    log = read_log(Path(str(o.log_path)))
    held = [r for r in log.of_kind("sample") if r["state"] == "holding"]
    assert len(held) == pytest.approx(1.0 * 250, abs=2)  # 1 s at the 250 Hz control rate
    assert max(r["advance"] for r in held) - min(r["advance"] for r in held) < 10e-6
    assert o.relaxation is not None
    assert o.relaxation.success, o.relaxation.message
    assert not o.relaxation.relaxes  # the robot scene's S8 is elastic
    assert o.as_dict()["relaxed_verdict"] is not None
    report = replay(Path(str(o.log_path)))
    assert report["identical"] is True
    assert report["replayed_relaxation"] == next(log.of_kind("estimate"))["relaxation"]


@pytest.mark.slow
def test_a_rehearsal_on_the_twin_calibrates_on_the_reference_then_estimates(
    tmp_path: Path,
) -> None:
    # palpate emulate --scene: the scene's samples at the bench file's poses (REF above the
    # sensor at target up, S8 below it at target down), compliant tube tips
    scene_path = tmp_path / "scene.yaml"
    scene_path.write_text(COMPLIANT, encoding="utf-8")
    scene = load(SceneConfig, scene_path)
    loaded = load_bench(bench_file(tmp_path, REHEARSAL))
    stations = stations_for(scene, loaded)
    assert [(st.sample, st.tube) for st in stations] == [("REF", "bent30"), ("S8", "bent30")]
    clock = VirtualClock()
    with SimulatedBench(loaded.stack, scene, clock=clock, wire=True, stations=stations) as sim:
        ref, s8 = run_session(
            loaded,
            plan_bench_trials(loaded),
            tmp_path / "logs",
            servo_port=sim.servo_port,
            board_port=sim.board_port,
            clock=clock,
            sync_to_clock=True,
        )
    assert ref.state == "done", ref.reason
    assert ref.calibration is not None
    assert ref.calibration.compliance == pytest.approx(1e-4, rel=0.1)
    assert s8.state == "done", s8.reason
    header = read_log(Path(str(s8.log_path))).header["estimator"]
    assert header["compliance_calibrated"] is True  # the session's own calibration
    assert s8.joint is not None
    assert s8.joint.covers(314.53e3)
    assert s8.status == "ok"
    assert replay(Path(str(s8.log_path)))["identical"] is True


@pytest.mark.slow
def test_a_fault_stops_the_session_and_skips_the_rest(tmp_path: Path) -> None:
    trials = "  - {target: up, sample: S8}\n" + ONE  # nothing above the sensor: no contact
    # without probing the approach's window is the plan's: no contact there is a guard's fault
    outcomes, torque, _ = session_on_ptys(tmp_path, trials, "campaign: {probe: false}\n")
    first, second = outcomes
    assert first.state == "fault"
    assert first.reason.startswith("no contact within")
    assert second.state == SKIPPED
    assert second.log_path is None
    assert torque == [False, False, False]
    assert read_log(Path(str(first.log_path))).complete


@pytest.mark.slow
def test_a_sample_probing_cannot_find_ends_unreachable_and_the_session_goes_on(
    tmp_path: Path,
) -> None:
    """Robot trials probe first (campaign.probe null): a first touch that finds no surface is a
    geometric answer (issue 25), not a fault: the trial ends unreachable and the next runs."""
    trials = "  - {target: up, sample: S8}\n" + ONE
    outcomes, _, _ = session_on_ptys(tmp_path, trials)
    first, second = outcomes
    assert first.state == "unreachable"
    assert first.reason.startswith("unreachable: probing: no surface within")
    assert second.state != SKIPPED
    assert read_log(Path(str(first.log_path))).complete


def test_dry_run_checks_and_shows_the_plan_without_opening_a_port(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = bench_file(tmp_path, ONE, "retract_mm: 5\ncampaign: {repeats: 2, standoff_mm: 2}\n")
    assert main(["trial", "--config", str(path), "--dry-run", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert [t["trial"] for t in out["trials"]] == ["01-down-S8-r0", "02-down-S8-r1"]
    t = out["trials"][0]
    assert t["standoff_translation_mm"] == pytest.approx(40.0)
    assert t["contact_translation_mm"] == pytest.approx(42.0)
    assert t["retract_translation_mm"] == pytest.approx(38.0)  # 35 would be behind home
    assert t["exposed_length_mm"] == pytest.approx(42.0)
    assert "no such device" in out["ports"]["servos"]["problem"]


def test_without_hardware_the_run_fails_cleanly_naming_the_port(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = bench_file(tmp_path, ONE)
    assert main(["trial", "--config", str(path)]) == 1
    err = capsys.readouterr().err
    assert f"{tmp_path}/ttyNOPE1: no such device" in err
    assert "serial.tools.list_ports" in err
    assert "Traceback" not in err


def test_the_shipped_bench_file_fails_cleanly_on_a_machine_without_the_bench() -> None:
    if os.path.exists("/dev/ttyACM0") or os.path.exists("/dev/ttyUSB0"):
        pytest.skip("this machine has serial devices at the shipped bench file's ports")
    done = subprocess.run(
        [sys.executable, "-m", "palpate.cli", "trial", "--config", "bench.yaml"],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert done.returncode == 1
    assert "/dev/ttyACM0: no such device" in done.stderr
    assert "Traceback" not in done.stderr


@pytest.mark.parametrize(
    ("extra", "trials", "message"),
    [
        ("torque: off\n", ONE, "torque: unknown key"),
        ("campaign: {tubes: [bent30]}\n", ONE, "campaign.tubes: describes a simulated campaign"),
        ("", "  - {target: nowhere}\n", "trials[0].target: no target named 'nowhere'"),
        ("", "  - {target: down, modulus_kpa: -3}\n", "trials[0].modulus_kpa: must be > 0"),
        ("campaign: {max_travel_past_contact_mm: 40}\n", ONE, "may reach 84.00 mm"),
        ("after_trial: limp\n", ONE, "after_trial: must be one of ['hold', 'release']"),
        (
            "campaign: {kind: bench}\n",
            "  - {target: down, exposed_length_mm: 25}\n",
            "trials[0].exposed_length_mm: 25 mm leaves a grating inside the tube",
        ),
    ],
)
def test_bad_bench_files_exit_2_naming_file_and_key(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: str, trials: str, message: str
) -> None:
    path = bench_file(tmp_path, trials, extra)
    assert main(["trial", "--config", str(path), "--dry-run"]) == 2
    err = capsys.readouterr().err
    assert message in err
    assert str(tmp_path) in err


def test_a_sensor_length_that_hides_a_grating_is_refused_naming_the_robot_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    robot = ROBOT_YAML + "sensor: {exposed_length_mm: 25}\n"
    path = bench_file(tmp_path, "  - {target: down}\n", "campaign: {kind: bench}\n", robot=robot)
    assert main(["trial", "--config", str(path), "--dry-run"]) == 2
    err = capsys.readouterr().err
    assert f"{tmp_path}/robot.yaml: sensor.exposed_length_mm: 25 mm leaves a grating" in err


def test_the_simulator_port_is_refused_on_the_bench(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = bench_file(tmp_path, ONE)
    path.write_text(path.read_text().replace(f"{tmp_path}/ttyNOPE0", "sim"), encoding="utf-8")
    assert main(["trial", "--config", str(path), "--dry-run"]) == 2
    assert "servos: port: 'sim' is not a device" in capsys.readouterr().err


def test_an_unknown_target_option_exits_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = bench_file(tmp_path, ONE)
    assert main(["trial", "--config", str(path), "--target", "sideways", "--dry-run"]) == 2
    assert "no target named 'sideways'" in capsys.readouterr().err
    # a stored pose the trial list does not name still runs on its own
    assert main(["trial", "--config", str(path), "--target", "up", "--dry-run"]) == 0


def test_port_errors_say_what_to_do() -> None:
    denied = serial.SerialException(errno.EACCES, "could not open port /dev/ttyUSB0: denied")
    msg = str(explain(denied, "/dev/ttyUSB0", "servo bus", "servos.port"))
    assert "/dev/ttyUSB0: permission denied" in msg
    assert "dialout" in msg
    busy = serial.SerialException(errno.EBUSY, "could not open port: busy")
    assert "busy. Another program holds it" in str(explain(busy, "/dev/ttyACM0", "board", "k"))
    silent = ServoTransportError("ping outer_roll: There is no status packet! (4 attempts)")
    msg = str(explain(silent, "/dev/ttyUSB0", "servo bus", "servos.port"))
    assert "opened but the servos do not answer" in msg
    assert "power supply" in msg


@pytest.mark.slow
def test_a_silent_servo_bus_is_reported_with_the_port(tmp_path: Path) -> None:
    """A pty nobody answers on: the port opens, no servo replies, torque was never on."""
    loaded = load_bench(bench_file(tmp_path, ONE))
    # the bench file's 2 s reply timeout, for a busy host, would spend 20 s of silence here
    servos = dataclasses.replace(loaded.stack.servos, timeout_ms=50.0)
    stack = dataclasses.replace(loaded.stack, servos=servos)
    clock = VirtualClock()
    with simulated(loaded, clock) as sim:
        master, slave = os.openpty()
        try:
            with (
                pytest.raises(HardwareError, match="do not answer") as info,
                open_hardware(
                    stack,
                    servo_port=os.ttyname(slave),
                    board_port=sim.board_port,
                    clock=clock,
                ),
            ):
                pass
        finally:
            os.close(master)
            os.close(slave)
    assert "servo bus port /dev/" in str(info.value)


@pytest.mark.hardware
def test_the_real_bench_opens_reads_and_releases() -> None:
    servo = os.environ.get("PALPATE_HW_SERVO_PORT")
    board = os.environ.get("PALPATE_HW_BOARD_PORT")
    if not (servo and board):
        pytest.skip("set PALPATE_HW_SERVO_PORT and PALPATE_HW_BOARD_PORT to test the bench")
    loaded = load_bench(resolve("bench.yaml"))
    with open_hardware(loaded.stack, servo_port=servo, board_port=board) as hw:
        joints, _ = hw.drive.read()  # no motion: read the encoders and the stream only
        frames = hw.reader.read_frames(20, timeout_s=2.0)
    assert math.isfinite(joints.translation)
    assert abs(joints.translation - loaded.stack.drive.home_translation) < 1e-4  # homed here
    assert len(frames) >= 20


@pytest.mark.parametrize("key", ["contact", "detector"])
def test_a_bench_file_reading_a_tip_grating_the_sensor_lacks_is_refused(
    key: str, tmp_path: Path
) -> None:
    path = bench_file(tmp_path, ONE, f"campaign: {{{key}: tip}}\n")
    with pytest.raises(ConfigError, match=f"campaign.{key}: 'tip' needs a tip force grating"):
        load_bench(path)
