"""The fuzz bench section: each target of :mod:`palpate.benchmarks.fuzztargets` (frame parser,
servo packets, driver replies, config loader) run long on a seeded numpy generator, with the
inputs run, the failures and the first failure reported per target.
"""

from __future__ import annotations

import os
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from palpate.benchmarks.fuzztargets import Rng, targets
from palpate.benchmarks.report import BenchContext, BenchSection, Table


def _run(
    target: Callable[[Rng], object], rng: Rng, budget_s: float, inputs: int = 10**9
) -> tuple[int, int, str]:
    """Run ``target`` on fresh inputs until ``inputs`` ran or ``budget_s`` of wall time passed:
    (inputs run, failures, the first failure)."""
    n = failures = 0
    first = ""
    deadline = time.perf_counter() + budget_s
    while time.perf_counter() < deadline and n < inputs:
        for _ in range(50):
            n += 1
            try:
                target(rng)
            except Exception as exc:  # a failure is what we count and report
                failures += 1
                first = first or f"{type(exc).__name__}: {exc}"[:200]
    return n, failures, first


def run(ctx: BenchContext) -> BenchSection:
    """Each target until ``PALPATE_FUZZ_INPUTS`` inputs (default 100,000) or
    ``PALPATE_FUZZ_SECONDS`` of wall time (default 600 s; 2 s with ``--quick``)."""
    budget = float(os.environ.get("PALPATE_FUZZ_SECONDS", "2" if ctx.quick else "600"))
    goal = int(os.environ.get("PALPATE_FUZZ_INPUTS", "100000"))
    rows: list[Sequence[Any]] = []
    summary: dict[str, Any] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name, target in targets(Path(tmp)).items():
            rng = np.random.default_rng(ctx.seed)
            t0 = time.perf_counter()
            n, failures, first = _run(target, rng, budget, goal)
            wall = time.perf_counter() - t0
            rows.append([name, n, failures, n / wall, first or "-"])
            summary[name] = {"inputs": n, "failures": failures, "first_failure": first}
    table = Table(
        f"Fuzzing (up to {goal} inputs or {budget:g} s per target, seed {ctx.seed})",
        ["target", "inputs", "failures", "inputs/s", "first failure"],
        rows,
        note="failure = an exception other than the documented ones, or a broken invariant",
    )
    return BenchSection("fuzz", [table], [], summary)
