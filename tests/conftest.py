"""Test-wide settings: seeded Hypothesis profile, a guard against leaked global state, and
turns for the tests that must run with no other test beside them (``pytest -n``)."""

from __future__ import annotations

import contextlib
import fcntl
import os
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

settings.register_profile(
    "ci",
    max_examples=60,
    derandomize=True,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile("long", max_examples=5000, deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))


@pytest.fixture(autouse=True)
def _no_leaked_numpy_error_state() -> object:
    """Fail any test that changes numpy's floating-point error handling and leaves it changed."""
    before = np.geterr()
    yield
    after = np.geterr()
    assert after == before, f"test leaked numpy error state: {before} -> {after}"


@pytest.fixture(scope="session")
def _turn_files(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path] | None:
    """The two lock files the workers of one ``pytest -n`` run share (None: one process)."""
    if "PYTEST_XDIST_WORKER" not in os.environ:
        return None
    shared = tmp_path_factory.getbasetemp().parent  # pytest-N/, above each worker's popen-gwK/
    return shared / "turn.gate", shared / "turn.lock"


@contextlib.contextmanager
def _flock(path: Path, kind: int) -> Iterator[None]:
    with path.open("a") as fh:
        fcntl.flock(fh, kind)
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


@pytest.fixture(autouse=True)
def _take_turns(
    request: pytest.FixtureRequest, _turn_files: tuple[Path, Path] | None
) -> Iterator[None]:
    """Under ``pytest -n``, a test marked ``alone`` (it measures nothing, but brings its own CPU
    load beside a real-time path, as the rehearsal does) runs with no test of another worker
    beside it: it holds ``turn.lock`` exclusively, every other test holds it shared. It first
    closes ``turn.gate``, which the others pass on their way in, so a stream of short tests
    cannot keep it waiting (a lock taken shared does not wait for one waiting to take it alone).
    """
    if _turn_files is None:
        yield
        return
    gate, lock = _turn_files
    if request.node.get_closest_marker("alone") is not None:
        with _flock(gate, fcntl.LOCK_EX), _flock(lock, fcntl.LOCK_EX):
            yield
        return
    with _flock(gate, fcntl.LOCK_SH):
        pass
    with _flock(lock, fcntl.LOCK_SH):
        yield


@pytest.fixture
def log_header() -> dict[str, object]:
    """The smallest trial-log header the log schema accepts (robot.records.logschema): what a
    reader relies on, nothing more."""
    return {
        "spec": {"kind": "bench", "exposed_length": 0.042},
        "section": {"EI": 1e-4, "EA": 1e4, "neutral_axis": 0.0, "fiber_offset": 1e-4,
                    "I_fiber": 1e-15, "I_wires": 1e-15},
        "sensor": {},
        "tube": None,
        "poisson": 0.45,
    }  # fmt: skip


@pytest.fixture
def log_sample() -> dict[str, object]:
    """A well-formed ``sample`` record of a trial log."""
    return {"kind": "sample", "t": 0.0, "state": "idle", "advance": 0.0, "roll": 0.0,
            "strains": [], "contact": False}  # fmt: skip
