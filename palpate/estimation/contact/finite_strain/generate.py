"""Regenerate the shipped departure rows:
``python -m palpate.estimation.contact.finite_strain.generate``.

Solves :func:`.departure.departure_row` for every Poisson ratio, base and layer of
``.table`` (POISSON x bonded/sliding x INVERSE_THICKNESS) on ``--workers`` processes (default 2;
~8 min on two cores) and writes ``departure.npz`` beside this module.
"""

from __future__ import annotations

import argparse
import itertools
import math
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from ....store.cache import write_npz
from .departure import ROW_POINTS, DepartureRow, departure_row
from .table import INVERSE_THICKNESS, POISSON, TABLE_PATH


def _solve(job: tuple[float, bool, float]) -> DepartureRow:
    nu, bonded, inv = job
    return departure_row(math.inf if inv == 0.0 else 1.0 / inv, nu, bonded)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args(argv)
    jobs = list(itertools.product(POISSON, (True, False), INVERSE_THICKNESS))
    shape = (len(POISSON), 2, len(INVERSE_THICKNESS), ROW_POINTS)
    names = ("depth", "frictionless", "sticking", "stick_spread")
    out = {name: np.zeros(shape) for name in names}
    start = time.monotonic()
    with ProcessPoolExecutor(args.workers) as pool:
        for n, (job, row) in enumerate(zip(jobs, pool.map(_solve, jobs), strict=True)):
            nu, bonded, inv = job
            index = (POISSON.index(nu), 0 if bonded else 1, INVERSE_THICKNESS.index(inv))
            out["depth"][index] = row.depth_ratio
            out["frictionless"][index] = row.frictionless
            out["sticking"][index] = row.sticking
            out["stick_spread"][index] = row.stick_spread
            print(
                f"{n + 1}/{len(jobs)} nu {nu} bonded {bonded} R/h {inv}: "
                f"{time.monotonic() - start:.0f} s",
                flush=True,
            )
    write_npz(TABLE_PATH, **out)
    print(f"wrote {TABLE_PATH}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
