"""The README's bench rehearsal, as a lab runs it, with both cores busy beside it.

``palpate emulate --scene config/scenes/robot.yaml --json`` and ``palpate trial --config
bench.yaml`` on the printed ports, as separate processes in real time (the real dynamixel-sdk
over the servo emulator's pty, pyserial over the board emulator's, recordings on), while two
processes spin: it exited 2 on every try ("lengths must be > 0 m" from the recording) and faulted
on the servo bus under load ("There is no status packet!") before issue 35. This is the one test
that runs in wall time: the rehearsal is a real-time path; nothing here asserts a time.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from mcap.reader import make_reader  # type: ignore[import-untyped,unused-ignore]

from benchmarks.rehearsal import cpu_load, rehearse
from palpate.robot.records.log import read_log


@pytest.mark.slow
@pytest.mark.alone  # its own load of two cores, not a third worker's tests beside it
def test_the_rehearsal_completes_with_a_joint_fit_beside_a_cpu_load(tmp_path: Path) -> None:
    with cpu_load(busy=2):
        session = rehearse(tmp_path)
    ended = [(t.get("state"), t.get("reason"), t.get("bus")) for t in session.trials]
    assert session.exit_code == 0, (
        f"{ended}\n{session.stderr[-2000:]}{session.emulator_stderr[-1000:]}"
    )
    assert session.trials
    for trial in session.trials:
        assert trial["state"] == "done", trial["reason"]
        assert trial["joint_kpa"] is not None
        low, high = trial["joint_ci_kpa"]
        assert low <= trial["joint_kpa"] <= high
        bus = trial["bus"]
        assert bus["transactions"] > 1000  # the servos answered the whole trial
        reads_failed = bus["failures"] - bus["write_failures"]  # a failed write holds its goal
        assert reads_failed <= bus["missed_reads"]  # no failed read went unhandled
        log = read_log(Path(trial["log"]))
        assert log.complete
        assert not log.problems
        with open(Path(trial["log"]).with_suffix(".mcap"), "rb") as fh:
            summary = make_reader(fh).get_summary()
        assert summary is not None
        assert summary.statistics is not None
        assert summary.statistics.message_count > 0
