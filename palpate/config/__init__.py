"""Configuration: YAML files shipped here and the one loader that validates them.

``load_stack("robot.yaml")`` returns a :class:`config.schema.StackConfig` in SI-ready form
(the YAML's millimetres in metres)::

    >>> from palpate.config import load_stack
    >>> stack = load_stack("robot.yaml")
    >>> stack.sensor.tip_radius, [tube.name for tube in stack.tubes]
    (0.0035, ['straight', 'bent15', 'bent30', 'bent50'])
"""

from __future__ import annotations

from pathlib import Path

from .loader import (
    CONFIG_DIR,
    ConfigError,
    InputError,
    from_mapping,
    load,
    read_yaml,
    resolve,
)
from .schema import StackConfig

__all__ = [
    "CONFIG_DIR",
    "ConfigError",
    "InputError",
    "StackConfig",
    "from_mapping",
    "load",
    "load_stack",
    "read_yaml",
    "resolve",
]


def load_stack(path: str | Path = "robot.yaml") -> StackConfig:
    """Load the robot/sensor configuration (default: the shipped simulated robot)."""
    return load(StackConfig, resolve(path))
