"""Trial logs: append-only JSON lines, flushed per record, self-describing, crash-safe.

One file per trial. Line 1 is the header (format name and version, trial id, what ran, the plan,
the sensor model the estimator needs). Then one record per line, each with a ``kind``:
``sample`` (one control tick), ``transition`` (state machine), ``estimate`` (the result) and
``end`` (the trial closed, with its final state and reason). Lines are flushed (and fsync'ed on
request) in batches: at every record that is not a ``sample`` (a state change, the estimate, the
end) and whenever the pending samples span ``flush_every_s`` (0.1 s) of their own time ``t``, so a
crash or SIGKILL keeps every record up to the last state change and loses at most 0.1 s of
samples after it; :attr:`TrialLogWriter.records` counts the lines on disk. A reader tells a
complete log (has ``end``) from a truncated one. (Batching: one flush per 25 ticks at 250 Hz
instead of one per line, about 5 % of a bench trial's CPU.)

Each record is checked against its kind's fields (:mod:`robot.records.logschema`, the one list of
kinds and fields). A header that fails is an error naming the file and the key; any other line
that fails is a bad line (its number and problem in :attr:`TrialLog.problems`), except a last
line cut short by a crash (no newline at its end), which only makes the log truncated.

Floats are written with ``repr`` precision (JSON's default), so replay is exact.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

from ...config.loader import InputError
from .logschema import LogRecordError, check_record
from .recording import McapRecorder

FORMAT = "palpate-trial-log"
VERSION = 1
# one encoder for every line (json.dumps builds one per call when given options)
_ENCODER = json.JSONEncoder(separators=(",", ":"), allow_nan=False)


def _clean(value: Any) -> Any:
    """JSON has no NaN/inf: write them as null (readers treat null as 'not measured')."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_clean(v) for v in value]
    return value


class TrialLogWriter:
    """Writes one trial's log. Use as a context manager; ``close`` is idempotent."""

    def __init__(
        self,
        path: str | Path,
        header: dict[str, Any],
        *,
        fsync: bool = False,
        flush_every_s: float = 0.1,
        mcap: bool = False,
        loads: Callable[[McapRecorder], list[float] | None] | None = None,
    ) -> None:
        if not flush_every_s >= 0:
            raise ValueError(f"flush_every_s must be >= 0, got {flush_every_s}")
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._fsync = fsync
        self._every = flush_every_s
        self.records = 0  # lines flushed to the OS (header included): what a crash keeps
        self.written = 0  # lines handed to write(), flushed or pending
        self._pending: list[str] = []
        self._pending_t0 = math.inf  # time ``t`` of the oldest pending sample
        self._fh: IO[str] | None = open(self.path, "x", encoding="utf-8")  # noqa: SIM115
        full = {"format": FORMAT, "version": VERSION, **header}
        # the MCAP recording beside it (robot.records.recording): every record, as it is written
        self.recording = McapRecorder(self.path.with_suffix(".mcap"), full) if mcap else None
        # the tip force the recording derives at its close (robot.trial.tipforce); the session
        # hands it the estimate's beam states once it has them
        self.loads = loads
        self.write({"kind": "header", **full})

    def write(self, record: dict[str, Any]) -> None:
        """Append one record; flushed at once unless it is a sample (see the module docstring)."""
        if self._fh is None:
            raise ValueError(f"trial log {self.path} is closed")
        try:  # the common case: nothing to clean, one pass
            line = _ENCODER.encode(record)
        except ValueError:  # a NaN or an infinity somewhere: written as null
            line = _ENCODER.encode(_clean(record))
        self._pending.append(line)
        self.written += 1
        if self.recording is not None:
            self.recording.write(record, line)
        t = record.get("t")
        if record.get("kind") != "sample" or not isinstance(t, float | int):
            self.flush()
            return
        self._pending_t0 = min(self._pending_t0, t)
        if t - self._pending_t0 >= self._every:
            self.flush()

    def flush(self) -> None:
        """Write the pending lines and flush them to the OS (fsync'ed on request), and the
        recording's messages with them."""
        if self.recording is not None:
            self.recording.flush()
        if self._fh is None or not self._pending:
            return
        self._fh.write("\n".join(self._pending) + "\n")
        self._fh.flush()
        if self._fsync:
            os.fsync(self._fh.fileno())
        self.records += len(self._pending)
        self._pending.clear()
        self._pending_t0 = math.inf

    def close(self) -> None:
        if self._fh is not None:
            self.flush()
            self._fh.close()
            self._fh = None
        if self.recording is not None:
            self.recording.close(self.loads)

    def __enter__(self) -> TrialLogWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


@dataclass
class TrialLog:
    """A log read back: header, records by kind, and whether it was closed properly."""

    path: Path
    header: dict[str, Any]
    records: list[dict[str, Any]] = field(default_factory=list)
    complete: bool = False
    bad_lines: int = 0  # a torn last line after a crash, or corruption
    problems: list[str] = field(default_factory=list)  # "line N: what is wrong", per bad line
    torn_tail: bool = False  # the last line was cut short (a crash while writing it)

    @property
    def damaged(self) -> list[str]:
        """The bad lines that a crash does not explain (all but a torn last line)."""
        return self.problems[:-1] if self.torn_tail else self.problems

    def of_kind(self, kind: str) -> Iterator[dict[str, Any]]:
        return (r for r in self.records if r.get("kind") == kind)

    @property
    def end(self) -> dict[str, Any] | None:
        return next(self.of_kind("end"), None)


class TrialLogError(InputError):
    """The file is not a trial log this version can read."""


def read_log(path: str | Path) -> TrialLog:
    """Read a trial log and check every record (:mod:`robot.records.logschema`); a bad line is
    counted and kept out of ``records``. Raises :class:`TrialLogError` naming the file (and the
    header's key) when the file is not a trial log this version reads."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise TrialLogError(f"{p}: no such trial log") from None
    except UnicodeDecodeError as exc:
        raise TrialLogError(f"{p}: not a trial log (not UTF-8 text: {exc.reason})") from None
    except OSError as exc:
        raise TrialLogError(f"{p}: cannot read: {exc.strerror or exc}") from None
    lines = text.split("\n")
    ended = lines[-1] == ""  # the file ends with a newline: no line was cut short
    if ended:
        lines.pop()
    if not lines:
        raise TrialLogError(f"{p}: empty file, not a trial log")
    log = TrialLog(path=p, header=_header(p, lines[0]))
    for number, line in enumerate(lines[1:], start=2):
        try:
            rec = json.loads(line)
            check_record(rec)
        except (ValueError, RecursionError) as exc:  # JSONDecodeError, LogRecordError
            problem = "not JSON" if isinstance(exc, json.JSONDecodeError) else str(exc)
            log.bad_lines += 1
            log.problems.append(f"line {number}: {problem}")
            log.torn_tail = not ended and number == len(lines)
            continue
        log.records.append(rec)
    log.complete = log.end is not None
    return log


def _header(p: Path, line: str) -> dict[str, Any]:
    try:
        header = json.loads(line)
    except (ValueError, RecursionError):
        raise TrialLogError(f"{p}: first line is not a JSON header") from None
    if not isinstance(header, dict) or header.get("format") != FORMAT:
        raise TrialLogError(f"{p}: not a {FORMAT} file")
    if header.get("version") != VERSION:
        raise TrialLogError(
            f"{p}: log version {header.get('version')!r:.20}, this reader knows {VERSION}"
        )
    try:
        if check_record(header) != "header":
            raise LogRecordError("kind", f"the first record is {header['kind']!r}, not a header")
    except LogRecordError as exc:
        raise TrialLogError(f"{p}: line 1: {exc}") from None
    return header
