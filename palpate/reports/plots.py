"""PNG figures like the paper's: estimates vs ground truth, force and strains vs advance."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from palpate.campaigns.campaign import SampleRow
from palpate.simulation.trial import TrialOutcome


def estimates_vs_truth(
    outcomes: Sequence[TrialOutcome], rows: Sequence[SampleRow], path: Path, title: str
) -> Path:
    """Every trial's estimate (dots) and each sample's mean (bar) against the actual modulus."""
    fig, ax = plt.subplots(figsize=(8, 4.5))
    names = [r.sample for r in rows]
    x = {n: i for i, n in enumerate(names)}
    ax.bar(
        [x[r.sample] - 0.2 for r in rows],
        [r.summary.actual / 1e3 for r in rows],
        width=0.4,
        label="actual",
        color="0.75",
    )
    ax.bar(
        [x[r.sample] + 0.2 for r in rows],
        [(r.summary.mean or 0.0) / 1e3 for r in rows],
        width=0.4,
        label="estimated (mean)",
        color="tab:blue",
    )
    for o in outcomes:
        if (m := o.modulus()) is not None:  # the method the table reports (joint fit)
            ax.plot(x[o.spec.sample] + 0.2, m / 1e3, "k.", ms=4)
    ax.set_xticks(range(len(names)), names)
    ax.set_ylabel("Young's modulus (kPa)")
    ax.set_title(title)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def trial_traces(outcome: TrialOutcome, path: Path) -> Path:
    """Force and grating strains against stage advance for one trial (as Fig. 4b,c), with the
    encoder positions the trial marked as contact (Eq. 14's X_contact) and buckling."""
    s = outcome.series
    adv = [a * 1e3 for a in s["advance"]]
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    ax1.plot(adv, s["force"], color="tab:red")
    ax1.set_ylabel("axial force P (N, world)")
    for key in ("s1", "s2", "s3"):
        if s.get(key):
            ax2.plot(adv[: len(s[key])], [v * 1e6 for v in s[key]], label=f"grating {key[1]}")
    ax2.set_ylabel("grating strain (ue)")
    ax2.set_xlabel("stage advance (mm)")
    m = outcome.marks
    for x, label, style in (
        (m.x_contact if m else None, "contact", ":"),
        (m.x_buckling if m else None, "buckling", "--"),
    ):
        if x is None:
            continue
        for ax in (ax1, ax2):
            ax.axvline(x * 1e3, color="0.3", linestyle=style, linewidth=1, label=label)
    ax1.legend(loc="upper left")
    ax2.legend()
    ax1.set_title(f"trial {outcome.spec.trial_id}")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def campaign_figures(
    outcomes: Sequence[TrialOutcome], rows: Sequence[SampleRow], out_dir: Path, name: str
) -> list[str]:
    """``palpate sim``'s PNG figures in the run folder: the estimates against the truth, the
    first trial's traces (when it ran in this process), the intervals and a trial's fit."""
    from palpate.reports.fitplot import fit_figures

    title = f"{name} campaign: estimated vs actual modulus"
    figures = [str(estimates_vs_truth(outcomes, rows, out_dir / "estimates.png", title))]
    if outcomes[0].series.get("advance"):  # not when the first trial was resumed
        figures.append(str(trial_traces(outcomes[0], out_dir / "trial_traces.png")))
    return figures + fit_figures(outcomes, out_dir, name)
