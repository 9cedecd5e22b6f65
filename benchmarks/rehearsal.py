"""The bench rehearsal as a lab runs it, under load: ``palpate emulate`` + ``palpate trial``.

Each session starts ``palpate emulate --scene SCENE --json`` (the servo-bus and board emulators
on pseudo-terminals, a world in front of them, real time), then ``palpate trial --config BENCH
--servo-port PTY --board-port PTY --json`` on the printed ports (the real ``dynamixel-sdk`` and
``pyserial``, recordings on), both as separate processes, exactly the README's commands. Beside
them, optionally, a CPU load: ``busy`` processes that spin (both cores of this machine busy), or
a ``palpate sim`` campaign. :func:`rehearse` returns what the trial printed and its exit code;
:func:`run` (``palpate bench --only rehearsal``) runs several sessions and tabulates the
trials' estimates, the bus's retries and missed reads, and the slowest reply it saw.

Used by ``tests/e2e/test_rehearsal.py`` (one session with both cores loaded) and by the
benchmark; nothing here asserts a time.

Usage::

    from benchmarks.rehearsal import cpu_load, rehearse
    with cpu_load(busy=2):
        session = rehearse(Path("/tmp/rehearsal"))
    assert session.exit_code == 0, session.stderr
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from benchmarks.report import BenchContext, BenchSection, Table
from palpate.config import resolve

SCENE = "scenes/robot.yaml"
BENCH = "bench.yaml"
PORTS_TIMEOUT_S = 120.0  # the emulators' start-up (imports, the world's first solve) on a busy host
TRIAL_TIMEOUT_S = 600.0  # a bound, never reached by a working session (about 40 s a trial)


@dataclass
class Session:
    """One rehearsal: the trial command's exit code, its JSON (None if it printed none), its
    stderr, and the emulator's."""

    exit_code: int
    result: dict[str, Any] | None
    stderr: str
    emulator_stderr: str = ""
    trials: list[dict[str, Any]] = field(default_factory=list)

    @property
    def why(self) -> str:
        """What ended the session short: a trial's reason, else the command's last error line."""
        for t in self.trials:
            if t["state"] != "done":
                return f"{t['trial']}: {t['state']}: {t['reason']}"
        lines = [x for x in self.stderr.splitlines() if x.strip()]
        return lines[-1] if lines else f"exit {self.exit_code}"

    @property
    def complete(self) -> bool:
        """Exit 0 and every trial done with a joint fit and its interval."""
        return (
            self.exit_code == 0
            and bool(self.trials)
            and all(
                t["state"] == "done" and t["joint_kpa"] is not None and t["joint_ci_kpa"]
                for t in self.trials
            )
        )


def _palpate(*args: str) -> list[str]:
    return [sys.executable, "-m", "palpate.cli", *args]


def rehearse(
    workdir: Path, *, scene: str = SCENE, bench: str = BENCH, extra: tuple[str, ...] = ()
) -> Session:
    """One session in ``workdir`` (logs under ``workdir/logs``): the emulators, then the trials
    on their ports; the emulators are stopped on return, whatever happened."""
    workdir.mkdir(parents=True, exist_ok=True)
    emu_err = workdir / "emulate.err"
    with (
        open(emu_err, "w", encoding="utf-8") as err,
        subprocess.Popen(
            _palpate("emulate", "--scene", str(resolve(scene)), "--bench", bench, "--json"),
            stdout=subprocess.PIPE,
            stderr=err,
            text=True,
        ) as emulator,
    ):
        try:
            ports = _ports(emulator)
            trial = subprocess.run(
                _palpate(
                    "trial",
                    "--config",
                    bench,
                    "--servo-port",
                    ports["dynamixel"],
                    "--board-port",
                    ports["board"],
                    "--log-dir",
                    str(workdir / "logs"),
                    "--json",
                    *extra,
                ),
                capture_output=True,
                text=True,
                timeout=TRIAL_TIMEOUT_S,
                check=False,
            )
        finally:
            emulator.terminate()
            try:
                emulator.wait(timeout=30)
            except subprocess.TimeoutExpired:
                emulator.kill()
                emulator.wait()
    result = None
    with contextlib.suppress(ValueError):
        result = json.loads(trial.stdout) if trial.stdout.strip() else None
    trials = list(result.get("trials", [])) if isinstance(result, dict) else []
    return Session(
        trial.returncode, result, trial.stderr, emu_err.read_text(encoding="utf-8"), trials
    )


def _ports(emulator: subprocess.Popen[str]) -> dict[str, str]:
    """The ports ``palpate emulate --json`` prints on its first line (it blocks until then)."""
    assert emulator.stdout is not None
    box: list[str] = []

    def read() -> None:
        box.append(emulator.stdout.readline() if emulator.stdout is not None else "")

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    reader.join(PORTS_TIMEOUT_S)
    if not box or not box[0].strip():
        raise RuntimeError(f"palpate emulate printed no ports within {PORTS_TIMEOUT_S:g} s")
    ports: dict[str, str] = json.loads(box[0])
    return ports


@contextlib.contextmanager
def cpu_load(busy: int = 0, campaign: bool = False) -> Iterator[None]:
    """``busy`` processes spinning and, with ``campaign``, ``palpate sim`` campaigns run one
    after another beside whatever runs inside; all killed on the way out."""
    scripts = ["while True: pass"] * busy
    if campaign:
        out = tempfile.mkdtemp(prefix="palpate-load-")
        scripts.append(
            "import subprocess, sys\n"
            "while True:\n"
            "    subprocess.run([sys.executable, '-m', 'palpate.cli', 'sim', '--no-plots', "
            f"'--no-mcap', '--out', {out!r}], stdout=subprocess.DEVNULL, "
            "stderr=subprocess.DEVNULL)\n"
        )
    # each load dies with this process however it dies (a killed benchmark left its load
    # running, and the next rehearsal measured a host four times over-committed)
    guard = (
        f"from palpate.campaigns.executors import die_with_parent; die_with_parent({os.getpid()})\n"
    )
    loads = [
        subprocess.Popen([sys.executable, "-c", guard + script], start_new_session=True)
        for script in scripts
    ]
    try:
        yield
    finally:
        for p in loads:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(p.pid, signal.SIGKILL)
            p.wait()


def run(ctx: BenchContext) -> BenchSection:
    """Sessions of the rehearsal with both cores loaded (two spinning processes and a
    ``palpate sim`` campaign): the trials' states and estimates, the bus's retries, missed
    reads and failures, its slowest answered attempt and transaction, and the replies slower
    than the packet timeout's 20 ms."""
    sessions = 2 if ctx.quick else 10
    table = Table(
        f"bench rehearsal under load ({sessions} sessions; emulate + trial on ptys, recordings "
        "on; 2 spinning processes and a palpate sim campaign beside)",
        [
            "session",
            "exit",
            "done",
            "joint fit kPa [95 %]",
            "transactions",
            "retries",
            "missed reads",
            "worst reply ms",
            "worst transaction ms",
            "replies > 20 ms",
            "why not complete",
        ],
    )
    complete = 0
    worst = 0.0
    with tempfile.TemporaryDirectory(prefix="palpate-rehearsal-") as tmp, cpu_load(2, True):
        for k in range(sessions):
            s = rehearse(Path(tmp) / f"s{k}")
            complete += s.complete
            bus = [t.get("bus") or {} for t in s.trials]
            reply = max((b.get("worst_reply_ms", 0.0) for b in bus), default=0.0)
            worst = max(worst, reply)
            slow = sum(b["replies_ms"]["50"] + b["replies_ms"]["inf"] for b in bus if b)
            table.rows.append(
                [
                    k,
                    s.exit_code,
                    f"{sum(t['state'] == 'done' for t in s.trials)}/{len(s.trials)}",
                    "; ".join(_joint(t) for t in s.trials),
                    sum(b.get("transactions", 0) for b in bus),
                    sum(b.get("retries", 0) for b in bus),
                    sum(b.get("missed_reads", 0) for b in bus),
                    reply,
                    max((b.get("worst_latency_ms", 0.0) for b in bus), default=0.0),
                    slow,
                    "" if s.complete else s.why,
                ]
            )
    table.note = (
        f"{complete} of {sessions} sessions complete (exit 0, every trial done with a joint "
        f"fit and its interval); the slowest answered attempt {worst:.1f} ms"
    )
    return BenchSection(
        "rehearsal", [table], summary={"complete": complete, "sessions": sessions, "worst": worst}
    )


def _joint(trial: dict[str, Any]) -> str:
    if trial.get("joint_kpa") is None:
        return f"- ({trial['state']})"
    low, high = trial["joint_ci_kpa"]
    return f"{trial['joint_kpa']:.1f} [{low:.1f}, {high:.1f}]"
