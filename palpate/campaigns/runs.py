"""Where a campaign writes: a new folder per run, never shared, never cleaning up earlier runs.

A run of ``palpate sim`` writes each scene's logs and plots under ``OUT/<scene>/<stamp>/`` (the
stamp is the local start time ``YYYYmmdd-HHMMSS``, with ``-2``, ``-3``, ... when two runs start in
the same second): the folder is created exclusively, so two runs never share one, and nothing
already under ``OUT`` is deleted. The folder holds ``run.json`` (what ran: the scene, seed, limit,
transport and a fingerprint of the configuration), its results (``palpate.reports.results``) and,
while a process writes there, ``.lock``, so a second writer (``--resume`` of a run still going)
is refused instead of mixing its logs in. A run that ends (done, error, Ctrl-C) removes its
lock; the lock dies with its process, so a run killed with SIGKILL leaves a free ``.lock``.

``--resume`` picks the newest folder of the scene whose ``run.json`` matches the run asked for
(same configuration, seed, limit and transport): its complete logs are kept and their trials
skipped; a log without its end record (the trial that was running when the run was killed) is
moved to ``logs/incomplete/`` and its trial runs again.
"""

from __future__ import annotations

import contextlib
import hashlib
import itertools
import json
import os
import re
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from palpate.config.loader import InputError

if sys.platform != "win32":  # POSIX advisory locks; on Windows runs keep apart by their folders
    import fcntl

RUN_FILE = "run.json"
LOCK_FILE = ".lock"
INCOMPLETE = "incomplete"
_STAMP = re.compile(r"^\d{8}-\d{6}(?:-(\d+))?$")


class RunDirError(InputError):
    """A run folder cannot be used: another process writes there, or there is none to resume."""


def fingerprint(*configs: object) -> str:
    """A short hash of loaded configuration objects (their dataclass reprs): two runs with the
    same fingerprint, seed and limit plan the same trials."""
    text = "\n".join(repr(c) for c in configs)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


def new_run_dir(base: Path) -> Path:
    """A new, empty folder ``base/<stamp>`` created by this call (never an existing one)."""
    base.mkdir(parents=True, exist_ok=True)
    stamp = time.strftime("%Y%m%d-%H%M%S")
    for n in itertools.count(1):
        path = base / (stamp if n == 1 else f"{stamp}-{n}")
        try:
            path.mkdir()
        except FileExistsError:
            continue
        return path
    raise AssertionError("unreachable")  # pragma: no cover


def _order(path: Path) -> tuple[str, int]:
    m = _STAMP.match(path.name)
    return (path.name[:15], int(m.group(1) or 1) if m else 0)


def run_dirs(base: Path) -> list[Path]:
    """The run folders under ``base``, oldest first."""
    if not base.is_dir():
        return []
    found = [p for p in base.iterdir() if p.is_dir() and _STAMP.match(p.name)]
    return sorted(found, key=_order)


def read_run_info(run_dir: Path) -> dict[str, Any] | None:
    """``run.json`` of a run folder, or None when it is missing or unreadable."""
    try:
        info = json.loads((run_dir / RUN_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return info if isinstance(info, dict) else None


def write_run_info(run_dir: Path, info: dict[str, Any]) -> None:
    (run_dir / RUN_FILE).write_text(json.dumps(info, indent=2) + "\n", encoding="utf-8")


def resumable(base: Path, info: dict[str, Any]) -> Path:
    """The newest run folder under ``base`` that ran what ``info`` describes."""
    for run_dir in reversed(run_dirs(base)):
        if read_run_info(run_dir) == info:
            return run_dir
    raise RunDirError(
        f"--resume: no earlier run under {base} with this configuration, seed and limit "
        f"(seed {info.get('seed')}, limit {info.get('limit')}, {info.get('transport')} path)"
    )


@contextlib.contextmanager
def locked(run_dir: Path) -> Iterator[Path]:
    """Hold ``run_dir``'s lock while inside; RunDirError when another process holds it."""
    if sys.platform == "win32":  # pragma: no cover
        yield run_dir
        return
    fd = os.open(run_dir / LOCK_FILE, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 32, 0).decode(errors="replace").strip() or "?"
            raise RunDirError(
                f"{run_dir}: another palpate run (pid {holder}) is writing there; "
                "wait for it to end or start a new run"
            ) from None
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        try:
            yield run_dir
        finally:  # still holding it: no other process can be using the file
            with contextlib.suppress(OSError):
                os.unlink(run_dir / LOCK_FILE)
    finally:
        os.close(fd)  # releases the lock


def set_aside(log: Path) -> Path:
    """Move an incomplete log to ``logs/incomplete/`` (kept, out of the run's logs)."""
    target_dir = log.parent / INCOMPLETE
    target_dir.mkdir(exist_ok=True)
    for n in itertools.count(1):
        target = target_dir / (log.name if n == 1 else f"{log.stem}.{n}{log.suffix}")
        if not target.exists():
            log.rename(target)
            return target
    raise AssertionError("unreachable")  # pragma: no cover
