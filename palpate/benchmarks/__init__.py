"""Benchmarks: speed against error, reported by ``palpate bench``.

Each section is a module exposing ``run(ctx: BenchContext) -> BenchSection``; the registry below
lists them in the order they print. Benchmarks measure; tests never assert timings.
"""

from __future__ import annotations

SECTIONS: dict[str, str] = {
    "mechanics": "palpate.benchmarks.mechanics",
    "sensor": "palpate.benchmarks.sensor",
    "robot": "palpate.benchmarks.robot",
    "campaign": "palpate.benchmarks.campaign",
    "sides": "palpate.benchmarks.sides",
    "probing": "palpate.benchmarks.probing",
    "estimation": "palpate.benchmarks.estimation",
    "tissue": "palpate.benchmarks.tissue",
    "tissue-fe": "palpate.benchmarks.tissue_fe",
    "hold": "palpate.benchmarks.hold",
    "live": "palpate.benchmarks.live",
    "fuzz": "palpate.benchmarks.fuzz",
    "rehearsal": "palpate.benchmarks.rehearsal",
}
