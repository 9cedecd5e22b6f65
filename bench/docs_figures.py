"""Every figure in docs/img, rebuilt from the code, and the data behind each beside it.

    python bench/docs_figures.py               # estimates.png and map-active.png (a few minutes)
    python bench/docs_figures.py --check       # recompute the data only and compare (CI)
    python bench/docs_figures.py --rehearsal   # also map-bench.png: the real-time bench
                                               # rehearsal on ptys (about 6 minutes)

Each figure is drawn from its JSON file (``docs/img/NAME.json``: the command that made it and
the numbers drawn), and the JSON from a seeded run of the code. ``--check`` reruns the seeded
runs and compares their numbers with the shipped JSON (relative 1e-3, verdicts exactly), so a
change that moves the README's figure fails CI until the figure is rebuilt. Exit 0 when every
figure's data is today's, 1 with each difference printed.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from same_results import differences  # bench/, beside this script

import palpate
from palpate.campaigns.survey import SurveyResult
from palpate.reports.mapfig import map_figure
from palpate.reports.plots import estimates_vs_truth

ROOT = Path(__file__).resolve().parent.parent
IMG = ROOT / "docs" / "img"
RTOL = 1e-3  # the tolerance results may move within (docs/speed.md)
ROW_KEYS = ("trial", "sample", "true_kpa", "joint_kpa", "joint_ci_kpa", "paper_kpa", "verdict")


Figure = tuple[dict[str, Any], Callable[[Path], object]]  # its data, and what draws it


def estimates() -> Figure:
    """The README's figure: the robot campaign (Table II), seed 0, each trial's estimates."""
    report = palpate.simulate(palpate.load_scene("scenes/robot.yaml"), seed=0, workers=2)
    rows = [{k: t.as_dict()[k] for k in ROW_KEYS} for t in report.trials]
    data = {"command": "palpate sim --campaign robot --seed 0", "rows": rows}
    title = "robot campaign: each trial's estimate against the truth"
    return data, lambda path: estimates_vs_truth(rows, path, title)


def map_active() -> Figure:
    """docs/maps.md's figure: the shipped map scene surveyed by the active plan, seed 0."""
    result: SurveyResult = palpate.survey(palpate.load_scene("scenes/maps/inclusion.yaml"), seed=0)
    d = result.as_dict()
    keep = ("inclusion_found", "inclusion_center_mm", "inclusion_radius_mm", "stopped")
    data = {
        "command": "palpate map --seed 0",
        "answer": {k: d.get(k) for k in keep},
        "probes": [p.record() for p in result.probes],
        "scores": result.scores(),
    }
    return data, lambda path: map_figure(result, path, "palpate map")


FIGURES: dict[str, Callable[[], Figure]] = {
    "estimates": estimates,
    "map-active": map_active,
}


def rehearsal_map(path: Path) -> None:
    """map-bench.png: ``palpate emulate`` with the map scene and ``palpate trial`` on its
    printed ports, each its own process, in real time (docs/maps.md, "On the bench")."""
    work = Path(tempfile.mkdtemp(prefix="palpate-rehearsal-"))
    emulate = subprocess.Popen(
        ["palpate", "emulate", "--scene", "config/scenes/maps/inclusion.yaml", "--bench",
         "bench-map.yaml", "--seconds", "900"],
        cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
    )  # fmt: skip
    try:
        ports = _ports(emulate)
        bench = (ROOT / "config" / "bench-map.yaml").read_text(encoding="utf-8")
        bench = re.sub(r"^log_dir:.*$", f"log_dir: {work / 'logs'}", bench, flags=re.M)
        bench_file = work / "bench-map.yaml"
        bench_file.write_text(bench, encoding="utf-8")
        for name in ("robot-stage.yaml", "targets.yaml"):
            shutil.copy(ROOT / "config" / name, work / name)
        subprocess.run(
            ["palpate", "trial", "--config", str(bench_file), "--servo-port", ports[0],
             "--board-port", ports[1]],
            cwd=ROOT, check=True,
        )  # fmt: skip
        shutil.copy(next((work / "logs").rglob("map.png")), path)
    finally:
        emulate.terminate()
        emulate.wait()


def _ports(emulate: subprocess.Popen[str]) -> tuple[str, str]:
    """The servo bus's and the board's ptys, as ``palpate emulate`` prints them."""
    assert emulate.stdout is not None
    found: dict[str, str] = {}
    deadline = time.monotonic() + 60
    while len(found) < 2 and time.monotonic() < deadline:
        line = emulate.stdout.readline()
        for key in ("dynamixel", "board"):
            m = re.search(r"/dev/pts/\d+", line)
            if m and key in line.lower():
                found[key] = m.group(0)
    if len(found) < 2:
        raise SystemExit("palpate emulate printed no ports within 60 s")
    return found["dynamixel"], found["board"]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="compare the data only (CI)")
    parser.add_argument("--rehearsal", action="store_true", help="also map-bench.png")
    parser.add_argument("--only", choices=sorted(FIGURES), help="one figure")
    args = parser.parse_args()
    os.chdir(ROOT)
    problems: list[str] = []
    for name, compute in FIGURES.items():
        if args.only and name != args.only:
            continue
        t0 = time.perf_counter()
        computed, draw = compute()
        data = json.loads(json.dumps(computed))
        shipped = IMG / f"{name}.json"
        print(f"{name}: data in {time.perf_counter() - t0:.0f} s", flush=True)
        if args.check:
            old = json.loads(shipped.read_text(encoding="utf-8")) if shipped.exists() else {}
            problems += [f"{name}{d}" for d in differences(old, data, rtol=RTOL)]
            continue
        shipped.write_text(json.dumps(data, indent=1) + "\n", encoding="utf-8")
        draw(IMG / f"{name}.png")
    if args.rehearsal and not args.check:
        rehearsal_map(IMG / "map-bench.png")
    for p in problems:
        print(p)
    if problems:
        print(f"{len(problems)} differences: rebuild with `python bench/docs_figures.py`")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
