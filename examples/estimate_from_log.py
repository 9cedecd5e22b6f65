"""An estimate from a recorded trial log: what a lab does with a log from its bench. Here the
log comes from one simulated trial (pass a log of your own instead); both estimates are re-run
on it and compared with the recorded ones, and the record is drawn with its fit.

    python examples/estimate_from_log.py [LOG.jsonl]
"""

from __future__ import annotations

import sys
from pathlib import Path

import palpate
from palpate.reports.fitplot import record_fit

if len(sys.argv) > 1:
    log_path = Path(sys.argv[1])
else:  # no log given: record one in simulation, as palpate trial records one on the bench
    scene = palpate.load_scene("scenes/bench.yaml")
    log_path = Path(palpate.simulate_trial(scene, 0, log_dir="logs").log_path or "")

log = palpate.read_log(log_path)
print(f"{log_path}: {len(list(log.of_kind('sample')))} samples, ended {log.end['state']}")
report = palpate.replay(log_path)
lo, hi = report["joint_ci_kpa"] or (None, None)
print(f"joint fit: {report['joint_kpa']:.1f} kPa, 95 % interval [{lo:.1f}, {hi:.1f}]")
print(f"the paper's single-point estimate (Eqs. 13-14): {report['paper_kpa']:.1f} kPa")
if report.get("truth_kpa") is not None:
    print(f"true modulus (simulation): {report['truth_kpa']:.1f} kPa")
print("reproduces the recorded estimates:", report["identical"])
print("figure:", record_fit(log, log_path.with_suffix(".png")))
