"""Speed against error of the mechanics, the signal chain and the servo bus.

The sections live in the checkout's ``benchmarks/`` (not installed with the package: a wheel
holds the product only); this command runs them from a checkout (an editable install), and
says so, exit 2, from an installed wheel.
"""

from __future__ import annotations

import argparse
import importlib
import json
import logging
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

from palpate.argtypes import non_negative_int
from palpate.config import InputError

log = logging.getLogger(__name__)

# the sections, in the order they print (benchmarks/__init__.py names each one's module; a test
# keeps the two equal)
SECTION_NAMES = (
    "mechanics",
    "sensor",
    "robot",
    "campaign",
    "sides",
    "probing",
    "estimation",
    "tissue",
    "tissue-fe",
    "hold",
    "live",
    "fuzz",
    "rehearsal",
)
CHECKOUT = Path(__file__).resolve().parents[2]  # palpate/commands/bench.py -> the checkout


def benchmarks() -> ModuleType:
    """The checkout's ``benchmarks`` package; InputError where there is none (a wheel)."""
    if (CHECKOUT / "benchmarks" / "__init__.py").exists() and str(CHECKOUT) not in sys.path:
        sys.path.insert(0, str(CHECKOUT))
    try:
        return importlib.import_module("benchmarks")
    except ModuleNotFoundError:
        raise InputError(
            "palpate bench runs from a checkout of the repository (its benchmarks/ are not "
            "installed): git clone, then pip install -e ."
        ) from None


def register(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--only", action="append", choices=SECTION_NAMES, help="run only these sections"
    )
    parser.add_argument("--quick", action="store_true", help="fewer repeats and a coarser grid")
    parser.add_argument("--out", type=Path, default=Path("out/bench"), help="folder for plots")
    parser.add_argument(
        "--seed", type=non_negative_int, default=0, help="seed of every random draw"
    )


def run(args: argparse.Namespace) -> int:
    package = benchmarks()
    report = importlib.import_module("benchmarks.report")
    repeats = 3 if args.quick else 7
    ctx = report.BenchContext(out_dir=args.out, quick=args.quick, seed=args.seed, repeats=repeats)
    names = args.only or list(SECTION_NAMES)
    results: list[Any] = []
    for name in names:
        module = importlib.import_module(package.SECTIONS[name])
        log.info("[bench] %s ...", name)
        section = module.run(ctx)
        results.append(section)
        if not args.json:
            for table in section.tables:
                print(table.render())
                print()
            for fig in section.figures:
                print(f"plot: {fig}")
            if section.figures:
                print()
    if args.json:
        payload = {
            s.name: {
                "tables": [t.as_dict() for t in s.tables],
                "figures": [str(f) for f in s.figures],
                "summary": s.summary,
            }
            for s in results
        }
        print(json.dumps(payload, indent=2, default=float))
    return 0
