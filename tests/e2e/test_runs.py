"""Runs never share files: each run of ``palpate sim`` writes to its own new folder, a second
writer is refused, earlier results are never deleted, a killed run resumes (``--resume``) to the
same table, a faulted trial makes the exit code 1, and pool workers die with their parent."""

from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from palpate.campaigns.runs import locked, run_dirs
from palpate.cli import main
from palpate.config import resolve

BENCH = ["sim", "--campaign", "bench", "--workers", "1", "--no-plots", "--json"]


def sim(out: Path, *extra: str, capsys: pytest.CaptureFixture[str]) -> tuple[int, dict]:  # type: ignore[type-arg]
    """Run ``palpate sim --json`` on the bench campaign; (exit code, payload or its stderr)."""
    code = main([*BENCH, "--out", str(out), *extra])
    captured = capsys.readouterr()
    if captured.out.strip():
        return code, json.loads(captured.out)
    return code, {"stderr": captured.err}


def trials(payload: dict) -> list[dict]:  # type: ignore[type-arg]
    """The trials' rows without where their logs are."""
    return [{k: v for k, v in t.items() if k != "log"} for t in payload["trials"]]


def test_two_runs_on_one_out_write_apart_and_delete_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, first = sim(tmp_path, "--limit", "2", capsys=capsys)
    assert code == 0
    first_logs = sorted(Path(first["log_dir"]).glob("*.jsonl"))
    before = {p: p.read_bytes() for p in first_logs}
    code, second = sim(tmp_path, "--limit", "2", "--seed", "1", capsys=capsys)
    assert code == 0
    assert second["log_dir"] != first["log_dir"]
    assert len(run_dirs(tmp_path / "bench")) == 2
    assert {p: p.read_bytes() for p in first_logs} == before  # untouched
    for payload in (first, second):  # each folder holds its own run's logs, and only those
        logs = sorted(p.stem for p in Path(payload["log_dir"]).glob("*.jsonl"))
        assert logs == sorted(t["trial"] for t in payload["trials"])
        assert all(Path(t["log"]).parent == Path(payload["log_dir"]) for t in payload["trials"])
        assert_results_on_disk(payload)


def assert_results_on_disk(payload: dict) -> None:  # type: ignore[type-arg]
    """The run folder holds what --json printed, a CSV row per trial and per sample, and no
    lock once the run ended."""
    run_dir = Path(payload["run_dir"])
    assert json.loads((run_dir / "results.json").read_text(encoding="utf-8")) == payload
    with open(run_dir / "trials.csv", encoding="utf-8", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert [r["trial"] for r in rows] == [t["trial"] for t in payload["trials"]]
    for row, t in zip(rows, payload["trials"], strict=True):
        assert row["verdict"] == t["verdict"]
        assert float(row["true_kpa"]) == t["true_kpa"]
        assert (row["joint_kpa"] == "") == (t["joint_kpa"] is None)
        assert (row["paper_kpa"] == "") == (t["paper_kpa"] is None)
    with open(run_dir / "samples.csv", encoding="utf-8", newline="") as fh:
        samples = list(csv.DictReader(fh))
    assert [s["sample"] for s in samples] == [s["sample"] for s in payload["samples"]]
    assert not (run_dir / ".lock").exists()


def test_a_second_writer_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, first = sim(tmp_path, "--limit", "1", capsys=capsys)
    assert code == 0
    run_dir = Path(first["log_dir"]).parent
    with locked(run_dir):  # another process writing there (a lock per open file: same effect)
        code, refused = sim(tmp_path, "--limit", "1", "--resume", capsys=capsys)
    assert code == 2
    assert "another palpate run" in refused["stderr"]


@pytest.mark.slow
def test_resume_reads_complete_trials_and_reruns_the_rest(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, whole = sim(tmp_path, "--limit", "3", capsys=capsys)
    assert code == 0
    logs = Path(whole["log_dir"])
    kept, cut, lost = (logs / f"{t['trial']}.jsonl" for t in whole["trials"])
    kept_bytes = kept.read_bytes()
    lines = cut.read_text(encoding="utf-8").splitlines(keepends=True)
    cut.write_text("".join(lines[: len(lines) // 2]), encoding="utf-8")  # killed mid-trial
    lost.unlink()  # killed before its log was opened
    table = (logs.parent / "trials.csv").read_text(encoding="utf-8")
    code, resumed = sim(tmp_path, "--limit", "3", "--resume", capsys=capsys)
    assert code == 0
    assert resumed["log_dir"] == whole["log_dir"]
    assert (logs.parent / "trials.csv").read_text(encoding="utf-8") == table  # kept whole
    assert_results_on_disk(resumed)
    assert trials(resumed) == trials(whole)  # the same table, bit for bit
    assert resumed["samples"] == whole["samples"]
    assert kept.read_bytes() == kept_bytes  # a complete trial is not run again
    assert (logs / "incomplete" / cut.name).exists()  # the torn log is kept, set aside
    assert cut.exists()
    assert lost.exists()


def test_resume_needs_an_earlier_run_of_the_same_command(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, _ = sim(tmp_path, "--limit", "1", capsys=capsys)
    assert code == 0
    code, refused = sim(tmp_path, "--limit", "1", "--seed", "5", "--resume", capsys=capsys)
    assert code == 2
    assert "no earlier run" in refused["stderr"]


FAULTING_SCENE = """name: faulting
robot: {robot}
campaign:
  kind: bench
  exposed_lengths_mm: [42, 44]
"""


def test_a_faulted_trial_exits_1_with_the_table_printed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A fiber strain guard the buckled beam must trip (50 ue, where the buckled beam bends
    past 1000 ue): the trial faults, the table is printed all the same, exit 1. (A travel window
    the beam cannot buckle in is an answer, not a fault: ``done``, verdict ``none``.)"""
    robot = tmp_path / "robot.yaml"
    text = resolve("robot.yaml").read_text(encoding="utf-8")
    assert "strain_limit_ue: 5000" in text
    robot.write_text(text.replace("strain_limit_ue: 5000", "strain_limit_ue: 50"), "utf-8")
    scene = tmp_path / "faulting.yaml"
    scene.write_text(FAULTING_SCENE.format(robot=robot), encoding="utf-8")
    argv = ["sim", "--scene", str(scene), "--workers", "1", "--no-plots", "--limit", "1"]
    assert main([*argv, "--out", str(tmp_path / "out")]) == 1
    out = capsys.readouterr().out
    assert "faulting campaign" in out
    assert "fault: fiber strain" in out.split("trials (", 1)[1]


def _children(pid: int) -> list[int]:
    tasks = Path(f"/proc/{pid}/task")
    return [int(c) for t in tasks.iterdir() for c in (t / "children").read_text().split()]


def _wait(condition: object, timeout_s: float, what: str) -> None:
    """Poll ``condition()`` until true; fail after a generous ``timeout_s`` of wall time."""
    assert callable(condition)
    deadline = time.monotonic() + timeout_s
    tick = threading.Event()
    while not condition():
        if time.monotonic() > deadline:
            pytest.fail(f"timed out waiting for {what}")
        tick.wait(0.05)  # a poll interval, not a wait for something to happen


@pytest.mark.slow
@pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="reads children from /proc")
def test_pool_workers_die_with_a_killed_parent(tmp_path: Path) -> None:
    argv = [sys.executable, "-m", "palpate", "-qq", "sim", "--campaign", "paper"]
    argv += ["--workers", "2", "--no-plots", "--out", str(tmp_path)]
    parent = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        _wait(lambda: len(_children(parent.pid)) >= 2, 120.0, "the pool's two workers")
        workers = _children(parent.pid)
        parent.send_signal(signal.SIGKILL)
        parent.wait(timeout=60)

        def gone() -> bool:
            return not any(Path(f"/proc/{w}").exists() and _is_ours(w) for w in workers)

        _wait(gone, 60.0, f"workers {workers} to end after their parent was killed")
    finally:
        if parent.poll() is None:
            parent.kill()
            parent.wait()


def _is_ours(pid: int) -> bool:
    """Still a process of this test (a reused pid would be another program, or a zombie)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z" and os.getpid() > 0
