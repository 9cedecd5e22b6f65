"""An existing trial log as an MCAP recording (``palpate export``): the same messages its trial
would have recorded as it ran (``robot.records.recording``)."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

from .log import read_log
from .recording import McapRecorder


def export(
    log_path: str | Path,
    out: str | Path | None = None,
    loads: Callable[[McapRecorder], list[float] | None] | None = None,
) -> Path:
    """The MCAP recording of an existing trial log (``<log>.mcap`` unless ``out``): the same
    messages its trial would have recorded, the tip force from ``loads``
    (``robot.trial.tipforce.axial_loads``). Raises ``TrialLogError`` for an unreadable log."""
    log = read_log(log_path)
    target = Path(out) if out is not None else Path(log_path).with_suffix(".mcap")
    recorder = McapRecorder(target, log.header)
    for record in log.records:
        recorder.write(record, json.dumps(record, separators=(",", ":"), allow_nan=False))
    recorder.close(loads)
    return target
