"""What ``palpate design`` and ``palpate.design`` are asked: :class:`DesignRequest`, the command's
options as typed fields, their defaults and checks stated once here.

    >>> DesignRequest((1.0, 20.0), poisson=0.7)
    Traceback (most recent call last):
    ...
    palpate.config.loader.InputError: <python>: poisson: must be in [0, 0.5], got 0.7
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

from palpate.argtypes import (
    float_in,
    non_negative_float,
    non_negative_int,
    number_list,
    number_range,
    positive_float,
    positive_int,
    positive_or_inf,
)
from palpate.campaigns.campaign import default_workers
from palpate.campaigns.designcheck import DEFAULT_TOLERANCE, UNITS
from palpate.config.loader import InputError
from palpate.sensor_design import DesignSpace
from palpate.sensor_design.lumen import LAW_DEPTH_RATIO

PYTHON = "<python>"  # the source named in a keyword's error
POSES = ("any", "vertical")  # how the sensor meets the tissue (``pose``)
_SPACE = DesignSpace()

# each numeric field's check, the command line's option type (palpate.argtypes) too
FIELD_TYPES: dict[str, Callable[[str], Any]] = {
    "modulus_range": number_range(positive_float),
    "poisson": float_in(0.0, 0.5),
    "thickness_mm": positive_or_inf,
    "imperfection": float_in(0.0, 0.1, high_open=True),
    "max_depth_ratio": float_in(0.0, LAW_DEPTH_RATIO, low_open=True),
    "resolution_multiple": positive_float,
    "fiber_radii_um": number_list(positive_float),
    "wire_diameters_um": number_list(positive_float),
    "wire_counts": number_list(non_negative_int),
    "tip_radii_mm": number_list(positive_float),
    "lumen_mm": positive_float,
    "clearance_mm": non_negative_float,
    "tip_resolution_mn": positive_float,
    "length_range_mm": number_range(positive_float),
    "moduli": positive_int,
    "lengths": positive_int,
    "contact_uncertainty_mm": non_negative_float,
    "seed": non_negative_int,
    "workers": positive_int,
    "tolerance_pct": float_in(0.0, 100.0, low_open=True),
    "tip_mass_g": non_negative_float,
}


@dataclass(frozen=True)
class DesignRequest:
    """What to design for and how to check it: ``palpate design``'s options by name, in their
    units (``thickness_mm``, ``tolerance_pct``, ``modulus_range`` in ``unit``). Each numeric
    field is checked as the command line checks its option (InputError naming the field)."""

    modulus_range: tuple[float, float]
    unit: str = "kPa"
    poisson: float = 0.45
    thickness_mm: float = 20.0  # inf: a half-space
    imperfection: float = 5e-4
    max_depth_ratio: float | None = None
    resolution_multiple: float = 20.0
    fiber_radii_um: tuple[float, ...] = tuple(r * 1e6 for r in _SPACE.fiber_radii)
    wire_diameters_um: tuple[float, ...] = tuple(d * 1e6 for d in _SPACE.wire_diameters)
    wire_counts: tuple[int, ...] = _SPACE.wire_counts
    tip_radii_mm: tuple[float, ...] = tuple(r * 1e3 for r in _SPACE.tip_radii)
    lumen_mm: float | None = None
    pose: str = "vertical"
    clearance_mm: float = 0.2
    tip_resolution_mn: float = 0.05
    length_range_mm: tuple[float, float] = (
        _SPACE.length_range[0] * 1e3,
        _SPACE.length_range[1] * 1e3,
    )
    config: str = "robot.yaml"
    scene: Path | None = None
    moduli: int = 4
    lengths: int = 3
    contact_uncertainty_mm: float = 0.0
    seed: int = 0
    workers: int = field(default_factory=default_workers)
    executor: str = "process"
    scheduler: str | None = None
    no_sim: bool = False
    tolerance_pct: float = 100 * DEFAULT_TOLERANCE
    tip_grating: bool = False
    tip_mass_g: float | None = None
    write: Path | None = None

    def __post_init__(self) -> None:
        if self.unit not in UNITS:
            raise InputError(f"{PYTHON}: unit: must be one of {sorted(UNITS)}, got {self.unit!r}")
        if self.pose not in POSES:
            raise InputError(f"{PYTHON}: pose: must be one of {list(POSES)}, got {self.pose!r}")
        for name, kind in FIELD_TYPES.items():
            value = getattr(self, name)
            if value is None:
                continue
            try:
                kind(as_option(name, value))
            except argparse.ArgumentTypeError as exc:
                raise InputError(f"{PYTHON}: {name}: {exc}") from None

    @classmethod
    def from_options(cls, options: argparse.Namespace) -> DesignRequest:
        """The request of ``palpate design``'s parsed options (already checked by their types)."""
        return cls(**{f.name: getattr(options, f.name) for f in fields(cls)})


def as_option(name: str, value: object) -> str:
    """A field's value as its option is written: ``1:20`` for a range, ``1,2.5`` for a list.

    >>> as_option("length_range_mm", (20.0, 100.0)), as_option("wire_counts", [0, 1, 2])
    ('20:100', '0,1,2')
    """
    if isinstance(value, tuple | list):
        sep = ":" if name.endswith(("range", "range_mm")) else ","
        return sep.join(f"{v:g}" for v in value)
    return repr(value)
