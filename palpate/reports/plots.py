"""PNG figures like the paper's: estimates vs ground truth, force and strains vs advance."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.ticker import FuncFormatter

from palpate.campaigns.campaign import SampleRow
from palpate.simulation.trial import TrialOutcome

STATUS_COLOURS = {"ok": "tab:green", "suspect": "tab:orange", "none": "0.6"}
DECADES = 1.0  # log axes once what is drawn spans more than this many decades (base 10)


@dataclass(frozen=True)
class _Point:
    """One trial as the headline figure draws it (kPa): x (its truth, spread a little within
    its sample), the truth, the joint fit (None without a number) and the paper's point."""

    x: float
    truth: float
    status: str
    joint: tuple[float, float | None, float | None] | None
    paper: float | None


def estimates_vs_truth(rows: Sequence[dict[str, Any]], path: Path, title: str) -> Path:
    """The headline figure, two panels over the true modulus: above, each trial's joint-fit
    estimate with its 95 % interval (coloured by verdict) and the paper's single point (Eqs.
    13-14) beside it, with y = x, on log axes where what is drawn spans decades; below, the
    same as estimate / truth, on an axis sized to the joint fit's intervals (a paper point
    beyond it drawn at the edge, pointing out), where a 1 % error shows. Drawn from the
    ``--json`` trial rows of ``palpate sim`` alone (``sample``, ``true_kpa``, ``joint_kpa``,
    ``joint_ci_kpa``, ``paper_kpa``, ``verdict``), so a figure in the docs is redrawn from the
    data it ships beside (``bench/docs_figures.py``)."""
    points = _points([r for r in rows if r.get("calibration") is None])
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7.5, 8.0), sharex=True)
    seen: set[str] = set()
    for pt in points:
        _draw(top, pt, 1.0, seen)
        _draw(bottom, pt, pt.truth, set(seen))
    values = [v for pt in points for v in _values(pt)]
    lo, hi = 0.8 * min(values), 1.25 * max(values)
    x_lo, x_hi = 0.8 * min(pt.truth for pt in points), 1.25 * max(pt.truth for pt in points)
    line = np.geomspace(x_lo, x_hi, 50)
    top.plot(line, line, color="k", lw=1, label="estimate = truth")
    if hi / lo > 10**DECADES:  # both: y = x stays a straight line
        top.set_xscale("log")
        top.set_yscale("log")
        for axis in (top.xaxis, top.yaxis):  # 300, not 3 x 10^2; minor ticks at 2, 3 and 5
            axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
            axis.set_minor_formatter(FuncFormatter(_minor_label))
    top.set_xlim(x_lo, x_hi)
    top.set_ylim(lo, hi)
    top.set_ylabel("estimated Young's modulus (kPa)", fontsize=10)
    top.legend(fontsize=9, loc="upper left")
    withheld = sum(1 for pt in points if pt.status == "none")
    if withheld:
        title += f"\n({withheld} of {len(points)} trials without a number: verdict none)"
    top.set_title(title, fontsize=11)
    _ratio_axis(bottom, points)
    bottom.set_xlabel(
        "true Young's modulus (kPa; the simulated world's). A sample's trials are spread "
        "+-6 % along x\nabout its true modulus so that they can be told apart",
        fontsize=9,
    )
    for ax in (top, bottom):
        ax.tick_params(labelsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def _minor_label(value: float, _: object) -> str:
    """A log axis's minor tick label: only at 2, 3 and 5 times a power of ten."""
    lead = f"{value:.0e}"[0]
    return f"{value:g}" if lead in "235" else ""


def _points(trials: Sequence[dict[str, Any]]) -> list[_Point]:
    """The trial rows as :class:`_Point` (kPa), spread by up to +-6 % of x within a sample."""
    groups: dict[str, list[int]] = {}
    for i, r in enumerate(trials):
        groups.setdefault(str(r["sample"]), []).append(i)
    spread = [0.0] * len(trials)
    for members in groups.values():
        for k, i in enumerate(members):
            spread[i] = 0.12 * ((k + 0.5) / len(members) - 0.5) if len(members) > 1 else 0.0
    points = []
    for r, dx in zip(trials, spread, strict=True):
        truth = float(r["true_kpa"])
        status = str(r.get("verdict") or "none")
        joint = None
        if r.get("joint_kpa") is not None and status != "none":
            lo, hi = r.get("joint_ci_kpa") or (None, None)
            joint = (float(r["joint_kpa"]), lo, hi)
        points.append(_Point(truth * (1 + dx), truth, status, joint, r.get("paper_kpa")))
    return points


def _values(pt: _Point) -> list[float]:
    joint = [v for v in (pt.joint or ()) if v is not None]
    return [pt.truth, *joint, *([pt.paper] if pt.paper is not None else [])]


def _draw(ax: Any, pt: _Point, per: float, seen: set[str]) -> None:
    """One trial's joint fit with its interval and the paper's point, divided by ``per``; each
    kind labelled once in the legend (``seen``)."""
    if pt.joint is not None:
        e, lo, hi = pt.joint
        yerr = None
        if lo is not None and hi is not None:
            yerr = [[max(e - lo, 0.0) / per], [max(hi - e, 0.0) / per]]
        label = None if pt.status in seen else f"joint fit, verdict {pt.status} (95 % interval)"
        colour = STATUS_COLOURS[pt.status]
        ax.errorbar([pt.x], [e / per], yerr=yerr, fmt="o", ms=4, color=colour, capsize=2,
                    lw=1, label=label)  # fmt: skip
        seen.add(pt.status)
    if pt.paper is not None and per == 1.0:
        label = None if "paper" in seen else "paper's single point (Eqs. 13-14)"
        ax.plot([pt.x], [pt.paper], "x", ms=5, color="tab:red", label=label)
        seen.add("paper")


def _ratio_axis(ax: Any, points: Sequence[_Point]) -> None:
    """The lower panel's axis: estimate / truth sized to the joint fit's intervals, the paper's
    points inside it as crosses and beyond it as triangles at the edge."""
    ax.axhline(1.0, color="k", lw=1)
    spans = [0.95, 1.05] + [
        v / pt.truth for pt in points if pt.joint is not None for v in pt.joint if v is not None
    ]
    low, high = min(spans), max(spans)
    pad = 0.1 * (high - low)
    low, high = low - pad, high + pad
    for pt in points:
        if pt.paper is None:
            continue
        ratio = pt.paper / pt.truth
        marker = "x" if low <= ratio <= high else ("^" if ratio > high else "v")
        ax.plot([pt.x], [min(max(ratio, low), high)], marker, ms=5, color="tab:red")
    ax.set_ylim(low, high)
    ax.set_ylabel("estimate / truth (^ v: paper beyond the axis)", fontsize=10)


def trial_traces(outcome: TrialOutcome, path: Path) -> Path:
    """Force and grating strains against stage advance for one trial (as Fig. 4b,c), with the
    encoder positions the trial marked as contact (Eq. 14's X_contact) and buckling."""
    s = outcome.series
    adv = [a * 1e3 for a in s["advance"]]
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    ax1.plot(adv, s["force"], color="tab:red", label="the world's force (simulation only)")
    ax1.set_ylabel("axial force P (N)", fontsize=10)
    for key in ("s1", "s2", "s3"):
        if s.get(key):
            ax2.plot(adv[: len(s[key])], [v * 1e6 for v in s[key]], label=f"grating {key[1]}")
    ax2.set_ylabel("grating strain (ue)", fontsize=10)
    ax2.set_xlabel("stage advance (mm)", fontsize=10)
    m = outcome.marks
    for x, label, style in (
        (m.x_contact if m else None, "contact mark (X_c)", ":"),
        (m.x_buckling if m else None, "buckling mark (X_b)", "--"),
    ):
        if x is None:
            continue
        for ax in (ax1, ax2):
            ax.axvline(x * 1e3, color="0.3", linestyle=style, linewidth=1, label=label)
    ax1.legend(loc="upper left", fontsize=9)
    ax2.legend(fontsize=9)
    ax1.set_title(f"the campaign's first trial: {outcome.spec.trial_id}", fontsize=11)
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

    title = f"{name} campaign: each trial's estimate against the truth"
    trial_rows = [o.as_dict() for o in outcomes]
    figures = [str(estimates_vs_truth(trial_rows, out_dir / "estimates.png", title))]
    if outcomes[0].series.get("advance"):  # not when the first trial was resumed
        figures.append(str(trial_traces(outcomes[0], out_dir / "trial_traces.png")))
    return figures + fit_figures(outcomes, out_dir, name)
