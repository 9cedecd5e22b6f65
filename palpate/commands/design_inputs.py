"""``palpate design``'s options: one per field of :class:`palpate.services.design.DesignRequest`,
whose defaults and checks they take (``FIELD_TYPES``), so the command line and ``palpate.design``
accept the same values; the work is the service's (``palpate.services.design``)."""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path
from typing import Any

from palpate.campaigns.designcheck import UNITS
from palpate.campaigns.executors import add_executor_arguments
from palpate.services.design_request import FIELD_TYPES, POSES, DesignRequest, as_option

_FIELDS = {f.name: f for f in dataclasses.fields(DesignRequest)}


def _default(name: str) -> Any:
    """The request's default for a field, as its option is written (``20:100``, ``1,2``)."""
    f = _FIELDS[name]
    value = f.default_factory() if f.default_factory is not dataclasses.MISSING else f.default
    return as_option(name, value) if isinstance(value, tuple) else value


def _option(parser: argparse.ArgumentParser, flag: str, help: str, **kw: Any) -> None:
    """An option of a request field: its type and default from :class:`DesignRequest`."""
    name = flag[2:].replace("-", "_")
    if name in FIELD_TYPES:
        kw.setdefault("type", FIELD_TYPES[name])
    if name != "modulus_range":
        kw.setdefault("default", _default(name))
    parser.add_argument(flag, help=help, **kw)


def register(parser: argparse.ArgumentParser) -> None:
    _add_tissue_arguments(parser)
    _add_space_arguments(parser)
    _add_check_arguments(parser)


def _add_tissue_arguments(parser: argparse.ArgumentParser) -> None:
    """The tissue to design for and what the design must resolve."""
    _option(parser, "--modulus-range", "tissue moduli, e.g. 1:10", required=True, metavar="MIN:MAX")
    _option(parser, "--unit", "of --modulus-range", choices=sorted(UNITS))
    _option(parser, "--poisson", "tissue Poisson ratio")
    _option(parser, "--thickness-mm", "tissue layer thickness (inf: half-space)")
    _option(
        parser,
        "--imperfection",
        "initial bow w0/L of the sensor (also used by the simulated campaign)",
    )
    _option(
        parser,
        "--max-depth-ratio",
        "the deepest delta/R at E_min the estimate may rely on (default 0.5, where the law's "
        "finite-strain bound reaches 5 %%; with --lumen-mm 1, the end of its tables: the bound, "
        "10 %%, is in the intervals)",
    )
    _option(parser, "--resolution-multiple", "smallest indentation at buckling, in encoder counts")


def _add_space_arguments(parser: argparse.ArgumentParser) -> None:
    """The candidates the search considers."""
    for flag, what in (
        ("--fiber-radii-um", "fiber radii"),
        ("--wire-diameters-um", "wire diameters"),
        ("--wire-counts", "numbers of NiTi wires"),
        ("--tip-radii-mm", "tip sphere radii"),
    ):
        _option(parser, flag, f"{what} to consider (comma-separated)")
    _option(
        parser,
        "--lumen-mm",
        "the working channel the whole sensor must pass (e.g. 2.8): tip, wires and fiber, the "
        "tip grating's element; implies --tip-grating with --tip-resolution-mn; reports the "
        "widest range one sensor spans through it and the second sensor's",
    )
    _option(
        parser,
        "--pose",
        "any: the design must carry its own weight held across (the search's weight check, a "
        "solid printed tip sphere; in the body the sensor meets tissue at any angle to "
        "gravity); vertical: the sag is only reported after the search",
        choices=POSES,
    )
    _option(parser, "--clearance-mm", "what a tool leaves of the channel")
    _option(
        parser,
        "--tip-resolution-mn",
        "with --lumen-mm, the tip grating's load resolution, 1 sigma (published: 0.25, 0.13, "
        "about 0.05 mN)",
    )
    _option(parser, "--length-range-mm", "exposed lengths to consider", metavar="MIN:MAX")


def _add_check_arguments(parser: argparse.ArgumentParser) -> None:
    """The robot the design is for and the simulated check of the chosen design."""
    _option(parser, "--config", "robot/sensor YAML (fiber, drive)")
    _option(parser, "--scene", "scene YAML whose fidelity and campaign settings the check uses",
            type=Path)  # fmt: skip
    _option(parser, "--moduli", "phantoms across the range")
    _option(parser, "--lengths", "exposed lengths per phantom: the window's two ends and the "
            "proposal, more between them; a window whose ends fail is narrowed by bisection and "
            "its middle simulated (1: the proposal only)")  # fmt: skip
    _option(parser, "--contact-uncertainty-mm", "contact-detection error (1 sigma) in the check")
    _option(parser, "--seed", "makes the simulated check reproducible")
    _option(
        parser,
        "--workers",
        "trials of the check run in parallel (processes, threads or local Dask workers)",
    )
    add_executor_arguments(parser)
    _option(parser, "--no-sim", "skip the simulated campaign", action="store_true")
    _option(
        parser,
        "--tolerance-pct",
        "the largest |relative error| of the joint fit on a phantom of the simulated check for "
        "the design to be usable",
    )
    _option(
        parser,
        "--tip-grating",
        "give the sensor a tip force grating (its sensitivity and range chosen against the "
        "noise) and check the design with it",
        action="store_true",
    )
    _option(
        parser,
        "--tip-mass-g",
        "the tip's mass for the weight check (default: sensor.tip_mass_g of --config)",
    )
    _option(
        parser,
        "--write",
        "write the robot configuration with the designed sensor here (what `palpate sim`, "
        "`emulate`, `trial` and `teleop` read: a scene's `robot:`, `--config`)",
        type=Path,
        metavar="YAML",
    )
