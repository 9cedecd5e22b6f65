"""Speed against error of the mechanics, the signal chain and the servo bus."""

from __future__ import annotations

import argparse
import importlib
import json
import logging
from pathlib import Path

from palpate.argtypes import non_negative_int
from palpate.benchmarks import SECTIONS
from palpate.benchmarks.report import BenchContext, BenchSection

log = logging.getLogger(__name__)


def register(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--only", action="append", choices=sorted(SECTIONS), help="run only these sections"
    )
    parser.add_argument("--quick", action="store_true", help="fewer repeats and a coarser grid")
    parser.add_argument("--out", type=Path, default=Path("out/bench"), help="folder for plots")
    parser.add_argument(
        "--seed", type=non_negative_int, default=0, help="seed of every random draw"
    )


def run(args: argparse.Namespace) -> int:
    repeats = 3 if args.quick else 7
    ctx = BenchContext(out_dir=args.out, quick=args.quick, seed=args.seed, repeats=repeats)
    names = args.only or list(SECTIONS)
    results: list[BenchSection] = []
    for name in names:
        module = importlib.import_module(SECTIONS[name])
        log.info("[bench] %s ...", name)
        section: BenchSection = module.run(ctx)
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
