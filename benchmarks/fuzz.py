"""The fuzz bench section: each target of :mod:`benchmarks.fuzztargets` (frame parser,
servo packets, driver replies, config loader) and :mod:`benchmarks.fuzzfiles` (replay
logs, scene YAML) run long on a seeded numpy generator, with the inputs run, the failures, the
hangs and the first failure reported per target.

A hang is an input that takes longer than ``PALPATE_FUZZ_HANG_S`` (default 60 s) of wall time:
a timer interrupts it (POSIX), and it counts as a failure too.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import tempfile
import time
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from types import FrameType
from typing import Any

import numpy as np

from benchmarks.fuzzfiles import file_targets
from benchmarks.fuzztargets import Rng, targets
from benchmarks.report import BenchContext, BenchSection, Table

FILE_TARGET_INPUTS = 10_000  # default inputs for the file targets (tens of ms each)


class FuzzHangError(Exception):
    """An input ran longer than the hang bound."""


@contextlib.contextmanager
def _hang_guard(seconds: float) -> Iterator[None]:
    """Interrupt the block with FuzzHangError after ``seconds`` (main thread, POSIX only)."""
    if sys.platform == "win32" or seconds <= 0:  # pragma: no cover
        yield
        return

    def expired(signum: int, frame: FrameType | None) -> None:
        raise FuzzHangError(f"no answer within {seconds:g} s")

    previous = signal.signal(signal.SIGALRM, expired)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def _run(
    target: Callable[[Rng], object],
    rng: Rng,
    budget_s: float,
    inputs: int = 10**9,
    hang_s: float = 60.0,
) -> tuple[int, int, int, str]:
    """Run ``target`` on fresh inputs until ``inputs`` ran or ``budget_s`` of wall time passed:
    (inputs run, failures, hangs, the first failure)."""
    n = failures = hangs = 0
    first = ""
    deadline = time.perf_counter() + budget_s
    while time.perf_counter() < deadline and n < inputs:
        n += 1
        try:
            with _hang_guard(hang_s):
                target(rng)
        except Exception as exc:  # a failure is what we count and report
            failures += 1
            hangs += isinstance(exc, FuzzHangError)
            first = first or f"{type(exc).__name__}: {exc}"[:200]
    return n, failures, hangs, first


def run(ctx: BenchContext) -> BenchSection:
    """Each target until ``PALPATE_FUZZ_INPUTS`` inputs (default 100,000; 10,000 for the file
    targets) or ``PALPATE_FUZZ_SECONDS`` of wall time (default 600 s; 2 s with ``--quick``).
    ``PALPATE_FUZZ_TARGETS`` (comma-separated names) runs only those targets."""
    budget = float(os.environ.get("PALPATE_FUZZ_SECONDS", "2" if ctx.quick else "600"))
    goal = os.environ.get("PALPATE_FUZZ_INPUTS")
    hang_s = float(os.environ.get("PALPATE_FUZZ_HANG_S", "60"))
    only = {t.strip() for t in os.environ.get("PALPATE_FUZZ_TARGETS", "").split(",") if t.strip()}
    rows: list[Sequence[Any]] = []
    summary: dict[str, Any] = {}
    with tempfile.TemporaryDirectory() as tmp:
        every = {**targets(Path(tmp)), **file_targets(Path(tmp))}
        for name, target in every.items():
            if only and name not in only:
                continue
            default = FILE_TARGET_INPUTS if name in ("replay logs", "scene yaml") else 100_000
            inputs = int(goal) if goal else default
            rng = np.random.default_rng(ctx.seed)
            t0 = time.perf_counter()
            n, failures, hangs, first = _run(target, rng, budget, inputs, hang_s)
            wall = time.perf_counter() - t0
            rows.append([name, n, failures, hangs, n / wall, first or "-"])
            summary[name] = {
                "inputs": n,
                "failures": failures,
                "hangs": hangs,
                "first_failure": first,
            }
    table = Table(
        f"Fuzzing (up to {goal or '100000 (files: 10000)'} inputs or {budget:g} s per target, "
        f"seed {ctx.seed}, hang bound {hang_s:g} s)",
        ["target", "inputs", "failures", "hangs", "inputs/s", "first failure"],
        rows,
        note="failure = an exception other than the documented ones, or a broken invariant",
    )
    return BenchSection("fuzz", [table], [], summary)
