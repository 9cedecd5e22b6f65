"""Benchmarks: speed against error, reported by ``palpate bench``.

Each section is a module exposing ``run(ctx: BenchContext) -> BenchSection``; the registry below
lists them in the order they print. Benchmarks measure; tests never assert timings.
"""

from __future__ import annotations

SECTIONS: dict[str, str] = {
    "mechanics": "benchmarks.mechanics",
    "sensor": "benchmarks.sensor",
    "robot": "benchmarks.robot",
    "campaign": "benchmarks.campaign",
    "sides": "benchmarks.sides",
    "probing": "benchmarks.probing",
    "estimation": "benchmarks.estimation",
    "tissue": "benchmarks.tissue",
    "tissue-fe": "benchmarks.tissue_fe",
    "hold": "benchmarks.hold",
    "live": "benchmarks.live",
    "fuzz": "benchmarks.fuzz",
    "rehearsal": "benchmarks.rehearsal",
}
