"""Tissue palpation with a buckling, FBG-sensorized beam: the control stack, its simulator and
its command line (``palpate``). From Python (docs/python-api.md)::

    import palpate

    report = palpate.simulate(palpate.load_scene("scenes/bench.yaml"), limit=2)
    print([t.modulus("joint") for t in report.trials])

The layers install under this name: ``palpate.config``, ``palpate.robot``, ``palpate.sensor``,
``palpate.estimation``, ``palpate.sim``, ``palpate.wire`` (docs/architecture.md).
"""

from typing import TYPE_CHECKING

from palpate.api import (
    design,
    load_robot,
    load_scene,
    read_log,
    read_recording,
    replay,
    scene_from_dict,
    simulate,
    simulate_trial,
    survey,
    trials,
)

if TYPE_CHECKING:
    from palpate.config.loader import ConfigError, InputError


def __getattr__(name: str) -> object:
    """``palpate.InputError`` and ``palpate.ConfigError``, loaded when first asked for: the
    command line's ``--help`` imports no configuration (nor YAML)."""
    if name in ("InputError", "ConfigError"):
        from palpate.config import loader

        return getattr(loader, name)
    raise AttributeError(f"module 'palpate' has no attribute {name!r}")


__all__ = [
    "ConfigError",
    "InputError",
    "design",
    "load_robot",
    "load_scene",
    "read_log",
    "read_recording",
    "replay",
    "scene_from_dict",
    "simulate",
    "simulate_trial",
    "survey",
    "trials",
]
