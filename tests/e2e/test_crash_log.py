"""Crash-safe logs: a trial in a child process is SIGKILLed mid-trial; every record it wrote
before the kill reads back, and replay reports the truncated log (exit 1)."""

from __future__ import annotations

import os
import select
import signal
import subprocess
from pathlib import Path

import pytest

from palpate.cli import main
from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.faults import child_command, fault_jobs
from palpate.robot.records.log import read_log
from palpate.robot.records.recording import read_recording

SCENE_PATH = resolve("scenes/faults.yaml")
SCENE = load(SceneConfig, SCENE_PATH)
STACK = load_stack(resolve(SCENE.robot))
READY_AFTER = 300  # log lines (header included) written before the parent kills the child


@pytest.mark.slow
def test_sigkill_mid_trial_keeps_every_record_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # a case with no fault scheduled: the child runs a normal trial until the parent kills it
    job = next(
        j for j in fault_jobs(SCENE, STACK, str(SCENE_PATH), 0, tmp_path, "fast")
        if j.case.name == "fbg-garbage"
    )  # fmt: skip
    argv, job_file = child_command(job, tmp_path / "box.json", ready_after_records=READY_AFTER)
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        assert proc.stdout is not None
        # the child writes one byte once READY_AFTER lines are in its log; wait for that
        # event (the bound only keeps a broken child from hanging the suite)
        ready, _, _ = select.select([proc.stdout], [], [], 300)
        assert ready, "the child never reported its log progress"
        assert os.read(proc.stdout.fileno(), 1) == b"R"
        os.kill(proc.pid, signal.SIGKILL)  # mid-trial: the child keeps writing records
        proc.wait()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        job_file.unlink(missing_ok=True)
        for stream in (proc.stdout, proc.stderr):
            if stream is not None:
                stream.close()
    assert proc.returncode == -signal.SIGKILL
    path = tmp_path / f"{job.spec.trial_id}.jsonl"
    lines = path.read_text(encoding="utf-8").split("\n")
    log = read_log(path)
    assert not log.complete  # no end record: the process died mid-trial
    assert 1 + len(log.records) >= READY_AFTER  # everything written before the signal is there
    # only the line being written at the instant of the kill may be torn
    assert log.bad_lines <= 1
    assert 1 + len(log.records) + log.bad_lines == len([x for x in lines if x])
    kinds = {r["kind"] for r in log.records}
    assert {"sample", "transition"} <= kinds
    assert main(["replay", str(path)]) == 1
    assert "truncated log" in capsys.readouterr().out
    # the MCAP recording beside it reads up to the kill: a message for every sample the log kept
    recording = read_recording(path.with_suffix(".mcap"))
    assert not recording.complete
    samples = sum(1 for r in log.records if r["kind"] == "sample")
    assert recording.count("/joint_states") >= samples
    assert recording.count("/palpate/transition") >= sum(
        1 for r in log.records if r["kind"] == "transition"
    )
    times = [t for t, _ in recording.messages["/joint_states"]]
    assert times == sorted(times)


def test_a_torn_last_line_is_counted_not_fatal(
    tmp_path: Path, log_header: dict[str, object], log_sample: dict[str, object]
) -> None:
    from palpate.robot.records.log import TrialLogWriter

    path = tmp_path / "t.jsonl"
    with TrialLogWriter(path, {"trial": "x", **log_header}) as w:
        w.write(log_sample)
        assert w.written == 2
        w.flush()
        assert w.records == 2
    with path.open("a", encoding="utf-8") as fh:
        fh.write('{"kind": "sam')
    log = read_log(path)
    assert log.bad_lines == 1
    assert log.torn_tail
    assert log.damaged == []  # a crash explains it
    assert len(log.records) == 1
    assert not log.complete


def test_a_bad_line_inside_is_damage_not_a_crash(
    tmp_path: Path, log_header: dict[str, object], log_sample: dict[str, object]
) -> None:
    from palpate.robot.records.log import TrialLogWriter

    path = tmp_path / "t.jsonl"
    with TrialLogWriter(path, {"trial": "x", **log_header}) as w:
        w.write({**log_sample, "advance": "abc"})
        w.write(log_sample)
    log = read_log(path)
    assert log.damaged == ["line 2: sample.advance: expected a number or null, got 'abc'"]
    assert not log.torn_tail
