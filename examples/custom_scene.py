"""A scene built in Python: three gels, one of them a thin layer on a rigid base, on the
bench; the joint fit against the truth, trial by trial, and the results files on disk.

    python examples/custom_scene.py [OUT_FOLDER]
"""

from __future__ import annotations

import sys
from pathlib import Path

import palpate

scene = palpate.scene_from_dict(
    {
        "name": "three-gels",
        "samples": [
            {"name": "soft", "modulus_kpa": 200.0, "poisson": 0.45},
            {"name": "medium", "modulus_kpa": 500.0, "poisson": 0.45},
            # 6 mm bonded to a rigid base: the estimator is told the thickness, as an operator
            # who cut the sample would be
            {"name": "thin", "modulus_kpa": 800.0, "poisson": 0.45, "thickness_mm": 6.0},
        ],
        "campaign": {"kind": "bench", "exposed_lengths_mm": [42, 46], "repeats": 1},
    }
)
out = Path(sys.argv[1] if len(sys.argv) > 1 else "three-gels")
report = palpate.simulate(scene, out=out)
print(f"{'trial':<28} {'truth':>7} {'joint fit [95 % interval]':>28} {'verdict':<8} {'paper':>7}")
for trial in report.trials:
    row = trial.as_dict()
    lo, hi = row["joint_ci_kpa"] or (float("nan"), float("nan"))
    joint = f"{row['joint_kpa']:.1f} [{lo:.1f}, {hi:.1f}]" if row["joint_kpa"] else "-"
    print(
        f"{row['trial']:<28} {row['true_kpa']:>7.1f} {joint:>28} {row['verdict']:<8} "
        f"{row['paper_kpa']:>7.1f}"
    )
print(f"results in {out}: {sorted(p.name for p in out.iterdir())}")
