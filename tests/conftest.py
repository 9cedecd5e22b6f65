"""Test-wide settings: seeded Hypothesis profile, and a guard against leaked global state."""

from __future__ import annotations

import os

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
