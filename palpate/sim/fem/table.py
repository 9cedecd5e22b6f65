"""Force-indentation tables: one per :class:`LayerProblem`, found on disk or solved once.

A table holds F / (E R^2) and a / R against delta / R for one dimensionless problem. It is
named by a key, the first 16 hex digits of the SHA-256 of the problem's parameters and of
``SOLVER_VERSION`` (bump it whenever a change to the solver changes any number), and stored as
``<key>.npz``. Lookup order: the tables shipped in this package (``sim/fem/tables``, regenerated
by ``python -m sim.fem.generate``), then the user's cache (``$PALPATE_CACHE_DIR``, default
``~/.cache/palpate/fe``), then a solve, whose table is written to the cache. A file is used
only if the key *and* the full parameter record stored in it equal the request, so a changed
parameter, a renamed file or a hash collision can never serve a stale table.

The solver (and scikit-fem, ~1 s to import) is imported only when a table must be solved.
"""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ...store.cache import cache_dir, parameter_record, record_key, write_npz
from .problem import LayerProblem

FloatArray = NDArray[np.float64]

SOLVER_VERSION = 1
"""Version of the numbers the solver produces; part of every key."""

SHIPPED_DIR = Path(__file__).with_name("tables")
_FIELDS = ("depths", "forces", "contact_radii")


@dataclass(frozen=True, eq=False)
class ForceTable:
    """A solved table (dimensionless).

    Attributes:
        key: the table's key (:func:`table_key`).
        problem: the problem it solves.
        depths: (k,) delta / R, increasing, k >= 1.
        forces: (k,) F / (E R^2).
        contact_radii: (k,) a / R.
        success: every requested depth converged (else the table stops early).
        message: the solver's message.
        build_seconds: wall time of the solve.
    """

    key: str
    problem: LayerProblem
    depths: FloatArray
    forces: FloatArray
    contact_radii: FloatArray
    success: bool
    message: str
    build_seconds: float


def _record(problem: LayerProblem) -> str:
    return parameter_record(SOLVER_VERSION, problem.as_dict())


def table_key(problem: LayerProblem) -> str:
    """16 hex digits naming the table of ``problem`` under the current ``SOLVER_VERSION``."""
    return record_key(_record(problem))


def save_table(table: ForceTable, directory: Path) -> Path:
    """Write ``table`` as ``<key>.npz`` in ``directory`` (atomically); returns the path."""
    return write_npz(
        directory / f"{table.key}.npz",
        record=np.array(_record(table.problem)),
        key=np.array(table.key),
        success=np.array(table.success),
        message=np.array(table.message),
        build_seconds=np.array(table.build_seconds),
        **{name: getattr(table, name) for name in _FIELDS},
    )


def read_table(problem: LayerProblem, directory: Path) -> ForceTable | None:
    """The table of ``problem`` stored in ``directory``, or None if absent or not this problem's
    (a different key or parameter record inside the file)."""
    key = table_key(problem)
    path = directory / f"{key}.npz"
    if not path.is_file():
        return None
    with np.load(path, allow_pickle=False) as data:
        if str(data["key"]) != key or str(data["record"]) != _record(problem):
            return None
        arrays = {name: np.array(data[name], dtype=np.float64) for name in _FIELDS}
        return ForceTable(
            key=key,
            problem=problem,
            success=bool(data["success"]),
            message=str(data["message"]),
            build_seconds=float(data["build_seconds"]),
            **arrays,
        )


def solve_table(problem: LayerProblem) -> ForceTable:
    """Solve ``problem`` (the finite-element run).

    Raises:
        RuntimeError: not even the first depth converged (the solver's message).
    """
    from .solver import solve_indentation

    start = time.perf_counter()
    result = solve_indentation(problem)
    seconds = time.perf_counter() - start
    if result.depths.size == 0:
        raise RuntimeError(f"finite-element table for {problem} failed: {result.message}")
    return ForceTable(
        key=table_key(problem),
        problem=problem,
        depths=result.depths,
        forces=result.forces,
        contact_radii=result.contact_radii,
        success=result.success,
        message=result.message,
        build_seconds=seconds,
    )


def solved_table(problem: LayerProblem) -> ForceTable | None:
    """The table of ``problem`` if it is shipped or cached already (None: not solved yet; this
    never solves)."""
    for directory in (SHIPPED_DIR, cache_dir()):
        table = read_table(problem, directory)
        if table is not None:
            return table
    return None


@functools.lru_cache(maxsize=64)
def load_table(problem: LayerProblem) -> ForceTable:
    """The table of ``problem``: shipped, else cached, else solved and cached (kept in memory)."""
    table = solved_table(problem)
    if table is not None:
        return table
    table = solve_table(problem)
    save_table(table, cache_dir())
    return table
