"""The calls the docstrings show run as written: the Python API's (``palpate.api``, what
``import palpate`` gives), each layer's front module's, and the helpers that carry one."""

from __future__ import annotations

import doctest
import importlib

import pytest

LAYER_FRONTS = (
    "palpate.config",
    "palpate.estimation",
    "palpate.robot",
    "palpate.sensor",
    "palpate.sim",
    "palpate.wire",
    "palpate.maps",
    "palpate.sensor_design",
    "palpate.estimation.reach",
    "palpate.estimation.pose.heartbeat",
    "palpate.estimation.pose.golden",
    "palpate.sim.heart",
    "palpate.estimation.trial.finished",
    "palpate.reports.mapresults",
    "palpate.services.design",
    "palpate.services.design_request",
)


def _run(name: str) -> doctest.TestResults:
    return doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS)


@pytest.mark.parametrize("name", LAYER_FRONTS)
def test_a_layer_s_front_module_shows_a_call_that_runs(name: str) -> None:
    result = _run(name)
    assert result.attempted > 0, f"{name} shows no call"
    assert result.failed == 0


@pytest.mark.slow
def test_every_function_of_the_python_api_shows_a_call_that_runs() -> None:
    import palpate.api

    calls = " ".join(
        example.source for t in doctest.DocTestFinder().find(palpate.api) for example in t.examples
    )
    public = set(palpate.__all__) - {"ConfigError", "InputError"}
    assert {name for name in public if f"{name}(" not in calls} == set()
    result = _run("palpate.api")
    assert result.failed == 0
