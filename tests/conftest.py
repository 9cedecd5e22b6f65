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
