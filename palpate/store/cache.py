"""The user's cache of solved tables: where it is, and arrays stored there under a record.

Tables that depend only on the configuration (the world's finite-element force tables,
``sim.fem.table``; the estimator's exact layer law, ``estimation.contact.layer_table``) are solved
once
and kept in ``$PALPATE_CACHE_DIR`` (default ``~/.cache/palpate/fe``) as ``.npz`` files named by
a hash of the parameters they were solved for; a file is used only when the full parameter
record stored in it equals the request, so a changed parameter or a stale file is never served.
A cache that cannot be written (read-only home) costs a solve each time, never an error.

Usage::

    arrays = cached_arrays("layer-paraboloid", record, lambda: {"chi": chi, "force": force})
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import tempfile
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

Arrays = dict[str, NDArray[np.float64]]


def parameter_record(version: int, parameters: Mapping[str, Any]) -> str:
    """The canonical text of a table's parameters under its solver's ``version``: what a table
    file stores and its key hashes."""
    return json.dumps({"solver_version": version, **parameters}, sort_keys=True)


def record_key(record: str) -> str:
    """16 hex digits naming the table of ``record`` (the first of its SHA-256)."""
    return hashlib.sha256(record.encode()).hexdigest()[:16]


def cache_dir() -> Path:
    """``$PALPATE_CACHE_DIR`` if set, else ``~/.cache/palpate/fe``."""
    env = os.environ.get("PALPATE_CACHE_DIR")
    return Path(env) if env else Path.home() / ".cache" / "palpate" / "fe"


def write_npz(path: Path, **arrays: object) -> Path:
    """Write ``arrays`` to ``path`` atomically (a temporary file beside it, then a rename)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".npz.tmp")
    os.close(fd)
    try:
        with open(tmp, "wb") as fh:
            np.savez(fh, **arrays)  # type: ignore[arg-type]
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return path


def cached_arrays(name: str, record: str, build: Callable[[], Arrays]) -> Arrays:
    """The float arrays stored as ``<name>-<hash of record>.npz`` in :func:`cache_dir` whose
    stored record equals ``record``; else ``build()``'s, written there for the next process.
    The arrays come back exactly as built (``.npz`` keeps float64 bit for bit)."""
    key = hashlib.sha256(f"{name}|{record}".encode()).hexdigest()[:16]
    path = cache_dir() / f"{name}-{key}.npz"
    with contextlib.suppress(OSError, ValueError, KeyError), np.load(path) as data:
        if str(data["record"]) == record:
            return {k: np.array(data[k], dtype=np.float64) for k in data.files if k != "record"}
    arrays = build()
    with contextlib.suppress(OSError):
        write_npz(path, record=np.array(record), **arrays)
    return arrays
