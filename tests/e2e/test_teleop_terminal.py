"""``palpate teleop`` as a person uses it: in a real terminal (tmux), keys in, screen out.

The emulators run in this test process on pseudo-terminals, in real time, with a world behind
the board (the hardware code path: dynamixel-sdk and pyserial on ptys). The program runs in a
tmux pane on its own server socket; the test presses keys with ``send-keys``, polls
``capture-pane`` until the screen shows what it waits for (with a generous deadline, never a
fixed sleep), and checks the servos' positions and torque in the emulator.

Real time on a shared machine: the emulators answer from threads that a busy machine may not
run for a while, so the program under test gets a robot file whose reply timeout and stale
stream timeout are generous (:func:`patient_robot`). The bench's 20 ms and 0.1 s are right on
dedicated hardware; here they would turn the machine's load into servo and stream faults.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
import yaml

from palpate.cli import main
from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.config.targets import load_targets
from palpate.simulation.twin import SimulatedBench
from palpate.wire.dynamixel import TICKS_PER_REV

needs_tmux = pytest.mark.skipif(
    shutil.which("tmux") is None, reason="tmux is not installed: the terminal tests need it"
)

STACK = load_stack()
TICKS_PER_MM = TICKS_PER_REV / STACK.drive.lead_mm_per_rev
TICKS_PER_DEG = TICKS_PER_REV / 360.0


class Terminal:
    """A tmux server of our own (socket in tmp) with one 100x32 window running ``command``."""

    def __init__(self, socket: Path, command: str) -> None:
        self.base = ["tmux", "-S", str(socket)]
        self._tmux("new-session", "-d", "-s", "t", "-x", "100", "-y", "32", command)

    def _tmux(self, *args: str) -> str:
        done = subprocess.run(
            [*self.base, *args], capture_output=True, text=True, timeout=60, check=True
        )
        return done.stdout

    def keys(self, *keys: str) -> None:
        self._tmux("send-keys", "-t", "t", *keys)

    def screen(self) -> str:
        return self._tmux("capture-pane", "-p", "-t", "t")

    def wait_for(
        self, *patterns: str, timeout: float = 90.0, within: float = 0.005, **near: float
    ) -> str:
        """Poll the screen until every regex matches and every ``label=value`` reading is
        ``within`` of the value (an encoder tick is 4.9 um of advance, 0.088 deg of roll);
        fail with the screen at the deadline."""
        deadline = time.monotonic() + timeout
        poll = threading.Event()
        while True:
            text = self.screen()
            if all(re.search(p, text) for p in patterns) and all(
                (v := reading(text, label)) is not None and abs(v - want) < within
                for label, want in near.items()
            ):
                return text
            if time.monotonic() > deadline:
                pytest.fail(f"screen never showed {patterns} {near}:\n{text}")
            poll.wait(0.03)  # a poll interval, not a wait for something to happen

    def program_pid(self) -> int:
        """The pid of the program the pane's shell runs (its only child)."""
        shell = int(self._tmux("display-message", "-p", "-t", "t", "#{pane_pid}"))
        children = Path(f"/proc/{shell}/task/{shell}/children").read_text().split()
        return int(children[0])

    def close(self) -> None:
        subprocess.run([*self.base, "kill-server"], capture_output=True, timeout=60, check=False)


def shell_command(argv: list[str]) -> str:
    """Run ``argv`` in the pane, then say how it ended and keep the pane open to read it."""
    return f"{shlex.join(argv)}; echo palpate exited $?; sleep 600"


def until(condition: Callable[[], bool], timeout: float = 60.0) -> bool:
    """Whether ``condition`` holds within ``timeout`` s of polling (a condition, not a wait for
    time to pass: it returns as soon as it holds)."""
    deadline = time.monotonic() + timeout
    poll = threading.Event()
    while not condition():
        if time.monotonic() > deadline:
            return False
        poll.wait(0.03)
    return True


def patient_robot(path: Path) -> Path:
    """The shipped robot file with a 2 s servo reply timeout and a 10 s stale-stream timeout,
    written to ``path``: the emulators' lateness on a loaded machine is not a fault here."""
    data = yaml.safe_load(resolve("robot.yaml").read_text(encoding="utf-8"))
    data["servos"]["timeout_ms"] = 2000
    data["board"]["stale_timeout_s"] = 10.0
    data["board"]["lost_timeout_s"] = 10.0
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return path


@pytest.fixture
def bench() -> Iterator[SimulatedBench]:
    scene = load(SceneConfig, resolve("scenes/robot.yaml"))
    with SimulatedBench(STACK, scene, wire=True) as sim:  # real time: no clock
        yield sim


def teleop_argv(sim: SimulatedBench, targets: Path, robot: Path) -> list[str]:
    """``palpate teleop`` on the simulated bench's ports, saving to ``targets``."""
    return [
        sys.executable,
        "-m",
        "palpate.cli",
        "teleop",
        "--servo-port",
        sim.servo_port,
        "--board-port",
        sim.board_port,
        "--targets",
        str(targets),
        "--robot",
        str(robot),
    ]


@pytest.fixture
def terminal(tmp_path: Path, bench: SimulatedBench) -> Iterator[Terminal]:
    argv = teleop_argv(bench, tmp_path / "targets.yaml", patient_robot(tmp_path / "robot.yaml"))
    term = Terminal(tmp_path / "tmux.sock", shell_command(argv))
    try:
        yield term
    finally:
        term.close()


def _goal_mm(text: str) -> float | None:
    """The advance goal shown on the screen's advance line."""
    m = re.search(r"^advance\s+[-+]?\d+\.\d+ mm\s+goal\s+([-+]?\d+\.\d+) mm", text, re.MULTILINE)
    return None if m is None else float(m.group(1))


def reading(text: str, label: str) -> float | None:
    """The first number on the screen line that starts with ``label``."""
    m = re.search(rf"^{label}\s+([-+]?\d+\.\d+)", text, re.MULTILINE)
    return None if m is None else float(m.group(1))


@pytest.mark.slow
@needs_tmux
def test_jog_save_emergency_stop_and_quit_in_a_terminal(
    tmp_path: Path, bench: SimulatedBench, terminal: Terminal
) -> None:
    terminal.wait_for(r"state\s+IDLE", "FBG stream ok", advance=0.0)
    translation = bench.servo("translation")
    outer = bench.servo("outer_roll")
    assert all(s.torque_enabled for s in bench.bus.servos)

    # one press, one step (1 mm by default)
    terminal.keys("Up")
    terminal.wait_for(r"state\s+IDLE", advance=1.0)
    assert abs(translation.position_ticks - 1.0 * TICKS_PER_MM) <= 3

    # ten presses at once: the goal never runs more than one step ahead of the stage
    terminal.keys(*["Up"] * 10)
    text = terminal.wait_for(r"goal\s+2\.\d+ mm", r"state\s+IDLE")
    goal = _goal_mm(text)
    assert goal is not None
    # IDLE means within the position tolerance of the goal: let the stage settle on it
    text = terminal.wait_for(r"state\s+IDLE", advance=goal, within=0.006)
    stopped = reading(text, "advance")
    assert stopped is not None
    assert 1.99 < stopped < 2.1, text  # one step on, not ten
    assert abs(translation.position_ticks - stopped * TICKS_PER_MM) <= 3

    terminal.keys("Right")
    terminal.wait_for(r"state\s+IDLE", roll=10.0, within=0.1)
    assert abs(outer.position_ticks - 10.0 * TICKS_PER_DEG) <= 3
    # the roll drags the stage through the gears' coupling; the drive takes it back out
    terminal.wait_for(r"state\s+IDLE", advance=stopped)

    # store the pose under a name
    terminal.keys("s")
    terminal.wait_for("name for this pose")
    terminal.keys("probe-1", "Enter")
    terminal.wait_for("saved pose 'probe-1'")
    stored = load_targets(tmp_path / "targets.yaml").get("probe-1")
    assert stored.tube == "straight"
    assert stored.translation_mm == pytest.approx(stopped, abs=0.005)
    assert stored.roll_deg == pytest.approx(10.0, abs=0.1)

    # emergency stop during a 5 mm jog: stops, retracts to home, holds
    terminal.keys("+", "Up")
    terminal.wait_for(r"goal\s+7\.0\d\d mm", r"state\s+POSITIONING")
    terminal.keys("Space")
    terminal.wait_for(r"state\s+ABORTED", advance=0.0)
    assert abs(translation.position_ticks) <= 3
    assert all(s.torque_enabled for s in bench.bus.servos)  # holding the retracted pose
    terminal.keys("Up")
    terminal.wait_for("press r to re-arm")

    # quit: the program ends and every servo is limp
    terminal.keys("q")
    terminal.wait_for("palpate exited 0", "torque off")
    assert not any(s.torque_enabled for s in bench.bus.servos)


@pytest.mark.slow
@needs_tmux
@pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="finds the pid through /proc")
def test_sigterm_releases_torque(bench: SimulatedBench, terminal: Terminal) -> None:
    terminal.wait_for(r"state\s+IDLE", "FBG stream ok", advance=0.0)
    terminal.keys("Up")
    terminal.wait_for(r"state\s+IDLE", advance=1.0)
    assert all(s.torque_enabled for s in bench.bus.servos)
    os.kill(terminal.program_pid(), signal.SIGTERM)
    terminal.wait_for("stopped \\(Terminated\\), torque off", "palpate exited 0")
    assert not any(s.torque_enabled for s in bench.bus.servos)


@needs_tmux
def test_missing_ports_are_named_on_the_screen(tmp_path: Path) -> None:
    argv = [sys.executable, "-m", "palpate.cli", "teleop"]
    argv += ["--servo-port", str(tmp_path / "ttyNOPE0"), "--board-port", str(tmp_path / "b")]
    term = Terminal(tmp_path / "tmux.sock", shell_command(argv))
    try:
        text = term.wait_for("palpate exited 1")
    finally:
        term.close()
    assert "no such device" in text.replace("\n", "")
    assert "Traceback" not in text


def test_without_a_terminal_it_refuses_with_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["teleop"]) == 2  # pytest's stdin is not a terminal
    assert "needs a terminal" in capsys.readouterr().err


NEAR_SCENE = """name: near
robot: {robot}
samples:
  - {name: S7, modulus_kpa: 1122.86}
campaign:
  exposed_length_mm: 12   # the sample 12 mm in front of the straight tube's tip
"""


@pytest.mark.slow
@needs_tmux
def test_the_default_simulator_shows_contact_and_strains(tmp_path: Path) -> None:
    """No ports: both emulators in-process with a tissue sample; jog into it and back."""
    scene = tmp_path / "near.yaml"
    robot = patient_robot(tmp_path / "robot.yaml")
    scene.write_text(NEAR_SCENE.replace("{robot}", str(robot)), encoding="utf-8")
    argv = [sys.executable, "-m", "palpate.cli", "teleop", "--scene", str(scene)]
    argv += ["--targets", str(tmp_path / "targets.yaml")]
    term = Terminal(tmp_path / "tmux.sock", shell_command(argv))
    try:
        # the first frame may come after the first screen: advancing waits for the stream
        term.wait_for(
            "simulator: sample S7", r"state\s+IDLE", "contact    no", "FBG stream ok", advance=0.0
        )
        term.keys("+", "]")  # 5 mm steps at 5 mm/s
        for mm in (5.0, 10.0):
            term.keys("Up")
            term.wait_for(r"state\s+IDLE", advance=mm)
        term.keys("Up")  # 15 mm would be 3 mm into the sample: held short of the 2.5 mm limit
        text = term.wait_for("contact    YES", "travel limit", r"state\s+IDLE")
        norm = reading(text, "norm")
        advance = reading(text, "advance")
        past = re.search(r"past contact\s+(\d+\.\d+) / 2\.50 mm", text)
        assert norm is not None
        assert norm > 100.0  # ue: the sensor is pressed on the sample
        assert advance is not None
        assert advance > 12.0
        assert past is not None
        assert 2.0 < float(past.group(1)) < 2.5  # measured from the contact event, as a trial
        assert "fault      -" in text
        term.keys("Space")
        term.wait_for(r"state\s+ABORTED", "contact    no", advance=0.0)
        term.keys("q")
        term.wait_for("palpate exited 0", "torque off")
    finally:
        term.close()


@needs_tmux
def test_the_x_y_stage_jogs_from_the_keyboard(tmp_path: Path) -> None:
    """A robot with an x-y stage (``stage:``): x and Y move its goal a step each, the stage's
    servos follow on the bus, the screen shows where it is."""
    data = yaml.safe_load(patient_robot(tmp_path / "plain.yaml").read_text(encoding="utf-8"))
    data["stage"] = yaml.safe_load(resolve("robot-stage.yaml").read_text(encoding="utf-8"))["stage"]
    robot = tmp_path / "robot.yaml"
    robot.write_text(yaml.safe_dump(data), encoding="utf-8")
    stack = load_stack(robot)
    assert stack.stage is not None
    scene = load(SceneConfig, resolve("scenes/robot.yaml"))
    with SimulatedBench(stack, scene, wire=True) as sim:
        argv = teleop_argv(sim, tmp_path / "targets.yaml", robot)
        term = Terminal(tmp_path / "tmux.sock", shell_command(argv))
        try:
            term.wait_for(r"state\s+IDLE", r"stage\s+x\s+\+0\.00\s+y\s+\+0\.00 mm")
            term.keys("x", "x", "Y")  # 1 mm steps: +2 mm in x, -1 mm in y
            term.wait_for(r"stage\s+x\s+\+2\.00\s+y\s+-1\.00 mm\s+goal \+2\.00, -1\.00 mm")
            per_mm = TICKS_PER_REV / stack.stage.lead_mm_per_rev
            # the screen rounds to 0.01 mm and shows the last read: wait for the servos to
            # settle on their goals (a loaded machine runs the emulator late), then compare
            settled = until(
                lambda: (
                    abs(sim.servo("stage_x").position_ticks - 2 * per_mm) <= 3
                    and abs(sim.servo("stage_y").position_ticks + 1 * per_mm) <= 3
                )
            )
            assert settled, (
                sim.servo("stage_x").position_ticks,
                sim.servo("stage_y").position_ticks,
            )
            term.keys("q")
            term.wait_for("palpate exited 0")
        finally:
            term.close()
