"""A stiffness sweep: one bench trial on each of eight gels from 100 to 1500 kPa, the joint
fit's estimate with its interval against the truth, drawn to sweep.png.

    python examples/stiffness_sweep.py [PNG]
"""

from __future__ import annotations

import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import palpate

moduli = np.geomspace(100.0, 1500.0, 8)
scene = palpate.scene_from_dict(
    {
        "name": "sweep",
        "samples": [
            {"name": f"E{e:.0f}", "modulus_kpa": float(e), "poisson": 0.45} for e in moduli
        ],
        "campaign": {"kind": "bench", "exposed_lengths_mm": [44], "repeats": 1},
    }
)
report = palpate.simulate(scene, workers=2)
truth, joint, low, high = [], [], [], []
for trial in report.trials:
    row = trial.as_dict()
    if row["joint_kpa"] is None:
        print(f"{row['trial']}: no number ({'; '.join(row['verdict_reasons'])})")
        continue
    truth.append(row["true_kpa"])
    joint.append(row["joint_kpa"])
    low.append(row["joint_kpa"] - row["joint_ci_kpa"][0])
    high.append(row["joint_ci_kpa"][1] - row["joint_kpa"])
    why = "; ".join(row["verdict_reasons"])
    verdict = row["verdict"] if row["verdict"] == "ok" or not why else f"{row['verdict']}: {why}"
    print(f"true {row['true_kpa']:7.1f} kPa, estimate {row['joint_kpa']:7.1f} kPa ({verdict})")

fig, ax = plt.subplots(figsize=(6, 4.5))
ax.errorbar(truth, joint, yerr=[low, high], fmt="o", capsize=3, label="joint fit (95 % interval)")
ax.plot(moduli, moduli, "k-", lw=1, label="estimate = truth")
ax.set(xscale="log", yscale="log", xlabel="true modulus (kPa)", ylabel="estimate (kPa)")
ax.legend()
path = sys.argv[1] if len(sys.argv) > 1 else "sweep.png"
fig.savefig(path, dpi=120)
print("figure:", path)
