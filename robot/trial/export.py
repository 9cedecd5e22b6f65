"""An existing trial log as an MCAP recording (``palpate export``): the same messages its trial
would have recorded as it ran (``robot.trial.recording``)."""

from __future__ import annotations

import json
from pathlib import Path

from palpate.robot.trial.log import read_log
from palpate.robot.trial.recording import McapRecorder, axial_loads


def export(log_path: str | Path, out: str | Path | None = None) -> Path:
    """The MCAP recording of an existing trial log (``<log>.mcap`` unless ``out``): the same
    messages its trial would have recorded. Raises ``TrialLogError`` for an unreadable log."""
    log = read_log(log_path)
    target = Path(out) if out is not None else Path(log_path).with_suffix(".mcap")
    recorder = McapRecorder(target, log.header)
    for record in log.records:
        recorder.write(record, json.dumps(record, separators=(",", ":"), allow_nan=False))
    recorder.close(axial_loads)
    return target
