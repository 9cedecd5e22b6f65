"""The inclusion's effect on force, per three-dimensional geometry: found on disk or solved once.

A :class:`RatioTable` holds, at the tabulated depths, the force of the layer with its
inclusions and the force of the same layer without them, both solved on the *same* grid
(:mod:`sim.fem3d.solver`). Their ratio is the inclusions' effect with the grid's discretisation
error cancelled to first order (the two share it); the world multiplies the validated
axisymmetric table of the homogeneous layer by it (:mod:`sim.fem3d.world`).

Storage as :mod:`sim.fem.table`: named by the first 16 hex digits of the SHA-256 of the
problem's parameters and ``SOLVER_VERSION``; the tables shipped in ``sim/fem3d/tables``
(``python -m sim.fem3d.generate``), then the user's cache (``$PALPATE_CACHE_DIR``), then a solve
(tens of seconds; a line on stderr says so), written to the cache. A file is used only when the
full parameter record in it equals the request.
"""

from __future__ import annotations

import functools
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ...store.cache import cache_dir, parameter_record, record_key, write_npz
from .problem import InclusionProblem

FloatArray = NDArray[np.float64]

SOLVER_VERSION = 1
"""Version of the numbers the 3-D solver produces; part of every key."""

SHIPPED_DIR = Path(__file__).with_name("tables")
_FIELDS = ("depths", "forces", "reference")


@dataclass(frozen=True, eq=False)
class RatioTable:
    """Forces of one 3-D problem with and without its inclusions (units E R^2).

    Attributes:
        key: :func:`ratio_key` of the problem.
        problem: what was solved.
        depths: (k,) delta / R.
        forces: (k,) with the inclusions.
        reference: (k,) without them, on the same grid.
        build_seconds: wall time of the two solves.
    """

    key: str
    problem: InclusionProblem
    depths: FloatArray
    forces: FloatArray
    reference: FloatArray
    build_seconds: float

    @property
    def ratios(self) -> FloatArray:
        """(k,) the inclusions' factor on the force at each depth."""
        return np.asarray(self.forces / self.reference, dtype=np.float64)


def _record(problem: InclusionProblem) -> str:
    return parameter_record(SOLVER_VERSION, problem.as_dict())


def ratio_key(problem: InclusionProblem) -> str:
    """16 hex digits naming the table of ``problem`` under the current ``SOLVER_VERSION``."""
    return record_key(_record(problem))


def save_ratios(table: RatioTable, directory: Path) -> Path:
    """Write ``table`` as ``inclusion-<key>.npz`` in ``directory`` (atomically)."""
    return write_npz(
        directory / f"inclusion-{table.key}.npz",
        record=np.array(_record(table.problem)),
        build_seconds=np.array(table.build_seconds),
        **{name: getattr(table, name) for name in _FIELDS},
    )


def read_ratios(problem: InclusionProblem, directory: Path) -> RatioTable | None:
    """The table of ``problem`` stored in ``directory``, or None if absent or another's."""
    key = ratio_key(problem)
    path = directory / f"inclusion-{key}.npz"
    if not path.is_file():
        return None
    with np.load(path, allow_pickle=False) as data:
        if str(data["record"]) != _record(problem):
            return None
        arrays = {name: np.array(data[name], dtype=np.float64) for name in _FIELDS}
        return RatioTable(key, problem, build_seconds=float(data["build_seconds"]), **arrays)


def solve_ratios(problem: InclusionProblem) -> RatioTable:
    """Solve ``problem`` and its homogeneous reference on the same grid.

    Raises:
        ContactError: a factorisation failed or a contact did not settle.
    """
    from .solver import forces

    start = time.perf_counter()
    depths, with_inclusions, _ = forces(problem)
    _, without, _ = forces(problem, homogeneous=True)
    return RatioTable(
        ratio_key(problem),
        problem,
        depths,
        with_inclusions,
        without,
        time.perf_counter() - start,
    )


def load_ratios(problem: InclusionProblem) -> RatioTable:
    """The table of ``problem``: shipped, else cached, else solved and cached (kept in memory;
    looked up in the frame of its solve, so problems that differ by a turn about the vertical
    share one)."""
    return _load(problem.canonical_problem())


@functools.lru_cache(maxsize=256)
def _load(problem: InclusionProblem) -> RatioTable:
    for directory in (SHIPPED_DIR, cache_dir()):
        table = read_ratios(problem, directory)
        if table is not None:
            return table
    print(
        f"palpate: solving a 3-D inclusion table ({len(problem.inclusions)} inclusion(s), "
        f"h/R = {problem.thickness_ratio:g}); once, then cached in {cache_dir()}",
        file=sys.stderr,
        flush=True,
    )
    table = solve_ratios(problem)
    save_ratios(table, cache_dir())
    return table
