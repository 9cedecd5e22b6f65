"""Figures that show the fit: a trial's force against indentation with the fitted model, and a
campaign's estimates with their intervals against the reference.

The trial figure is drawn from the trial's log alone (so ``palpate replay --plot`` draws it for
any log, simulated or from the bench): the loading record's axial load and depth from the
strains (the estimator's beam states), the depth measured from the joint fit's contact
``delta = u - x0 - e - c P``; the fitted model ``P0 + E f(delta)`` at the best hypothesis; the
fitted contact (delta = 0, with its interval); the paper's single point (Eqs. 13-14: its depth
from the contact event and the buckling mark, its load from the elastica); for a trial that held
after buckling, the held samples in their own colour; and the model at the moduli the log's
header knows (the world's truth in simulation, the stated reference), so an interval that
misses them shows. Nothing else of the simulated world is drawn.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.lines import Line2D

from palpate.config.loader import InputError
from palpate.estimation.belief import Hypothesis
from palpate.estimation.trial.inputs import header_sensor
from palpate.estimation.trial.relaxed import HOLD_STATE, RECORD_STATES
from palpate.estimation.trial.states import record_states
from palpate.reports.replay import known_moduli
from palpate.robot.records.log import TrialLog, read_log

STATUS_COLOURS = {"ok": "tab:green", "suspect": "tab:orange", "none": "0.6"}


def record_fit(log: TrialLog, path: Path) -> Path:
    """The trial's force-indentation record with its fit (see the module docstring) as a PNG at
    ``path``. Raises ValueError when the log has no joint fit to draw."""
    estimate = next(log.of_kind("estimate"), None)
    joint = None if estimate is None else estimate.get("joint")
    if not isinstance(joint, dict) or joint.get("modulus") is None or joint.get("best") is None:
        raise InputError(f"{log.path}: no joint fit to draw (the trial has no estimate)")
    sensor, section, inputs = header_sensor(log.header, str(log.path))
    gratings = len(sensor.used_gratings)
    rows = [r for r in log.of_kind("sample") if r["state"] in RECORD_STATES]
    rows = [r for r in rows if len(r["strains"]) == gratings and r["advance"] is not None]
    advance = np.array([r["advance"] for r in rows], dtype=np.float64)
    strains = np.array([r["strains"] for r in rows], dtype=np.float64).reshape(-1, gratings)
    states, _ = record_states(advance, strains, inputs, sensor, section)
    best = Hypothesis.described(joint["best"], inputs.contact_radius, inputs.belief().layer_law)
    law, compliance = best.law, best.compliance
    x0, offset = float(joint["contact"]), float(joint.get("load_offset") or 0.0)
    depth = advance - states.e - compliance * states.P - x0
    held = np.array([r["state"] == HOLD_STATE for r in rows])
    fig, ax = plt.subplots(figsize=(7, 4.5))
    mm = 1e3
    ax.plot(depth[~held] * mm, states.P[~held], ".", ms=2, color="0.35", label="record (strains)")
    if held.any():
        ax.plot(depth[held] * mm, states.P[held], ".", ms=2, color="tab:purple", label="hold")
    grid = np.linspace(min(depth.min(), 0.0), depth.max(), 300)
    model = offset + float(joint["modulus"]) * law.shape(grid)[0]
    label = f"joint fit: E = {joint['modulus'] / 1e3:.0f} kPa {_interval(joint)}"
    ax.plot(grid * mm, model, color="tab:blue", lw=1.5, label=label)
    relaxation = (estimate or {}).get("relaxation") or {}
    if relaxation.get("relaxes") and relaxation.get("relaxed") is not None:
        relaxed = offset + float(relaxation["relaxed"]) * law.shape(grid)[0]
        text = f"relaxed: E_inf = {relaxation['relaxed'] / 1e3:.0f} kPa"
        ax.plot(grid * mm, relaxed, color="tab:purple", lw=1.2, ls="--", label=text)
    for name, (modulus, style) in _known(log.header).items():  # what the log knows besides
        curve = offset + modulus * law.shape(grid)[0]
        ax.plot(
            grid * mm, curve, color="k", lw=1, ls=style, label=f"{name}: {modulus / 1e3:.0f} kPa"
        )
    _contact(ax, joint, x0)
    _paper(ax, estimate)
    verdict = (estimate or {}).get("verdict") or {}
    status = verdict.get("status", "-")
    ax.set_title(f"trial {log.header.get('trial')}: verdict {status}")
    ax.set_xlabel("indentation from the fitted contact (mm)")
    ax.set_ylabel("axial load P from the strains (N)")
    ax.legend(loc="upper left", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def _known(header: dict[str, Any]) -> dict[str, tuple[float, str]]:
    """The moduli the log knows (``replay.known_moduli``) as the model curves to draw beside
    the fit: the world's truth (simulation) and the stated reference, each with its style."""
    known = known_moduli(header)
    names = {
        "truth": ("true modulus (simulation)", "--"),
        "reference": ("reference measurement", ":"),
    }
    return {names[k][0]: (float(v), names[k][1]) for k, v in known.items() if v is not None}


def _interval(joint: dict[str, Any]) -> str:
    lo, hi = joint.get("ci_low"), joint.get("ci_high")
    return "" if lo is None or hi is None else f"[{lo / 1e3:.0f}, {hi / 1e3:.0f}]"


def _contact(ax: Any, joint: dict[str, Any], x0: float) -> None:
    """The fitted contact (delta = 0) and its interval, in the record's depth coordinate."""
    ax.axvline(0.0, color="tab:blue", ls=":", lw=1, label="fitted contact")
    lo, hi = joint.get("contact_low"), joint.get("contact_high")
    if lo is not None and hi is not None:
        ax.axvspan((lo - x0) * 1e3, (hi - x0) * 1e3, color="tab:blue", alpha=0.12)


def _paper(ax: Any, estimate: dict[str, Any] | None) -> None:
    """The paper's single point at its own depth (from its contact event to its buckling mark)
    and load: where it sits off the record shows what its contact event cost it."""
    if estimate is None or estimate.get("delta") is None or estimate.get("force") is None:
        return
    delta, force = float(estimate["delta"]), float(estimate["force"])
    modulus = estimate.get("modulus")
    what = "" if modulus is None else f": {modulus / 1e3:.0f} kPa"
    ax.plot([delta * 1e3], [force], "r^", ms=7, label=f"paper (Eqs. 13-14){what}")


def estimates_with_intervals(rows: Sequence[dict[str, Any]], path: Path, title: str) -> Path:
    """Each trial's joint estimate with its 95 % interval (coloured by verdict) and the paper's
    estimate beside it, relative to the true modulus (1), the sample's reference measurement
    (what a lab would have measured it to be, with its error: the paper's Table I column)
    dashed, from the ``--json`` trial rows of ``palpate sim`` (``joint_kpa``,
    ``joint_ci_kpa``, ``paper_kpa``, ``verdict``, ``true_kpa``, ``reference_kpa``). Trials are
    grouped by sample, named below. The axis spans the joint fit's intervals; a paper estimate
    beyond it is drawn at the edge, pointing out."""
    fig, ax = plt.subplots(figsize=(max(7.0, 0.18 * len(rows) + 3), 5.2))
    ax.axhline(1.0, color="k", lw=1)
    spans: list[float] = [0.9, 1.1]
    papers: list[tuple[int, float]] = []
    shown: set[str] = set()
    for i, r in enumerate(rows):
        truth = r.get("true_kpa")
        if not truth:
            continue
        if r.get("reference_kpa") is not None:
            ref = r["reference_kpa"] / truth
            ax.plot([i - 0.4, i + 0.4], [ref, ref], color="0.5", lw=1, ls="--")
            spans.append(ref)
            shown.add("reference")
        status = str(r.get("verdict"))
        if r.get("joint_kpa") is not None:
            spans += _joint_bar(ax, i, r, truth, STATUS_COLOURS.get(status, "0.6"))
            shown.add(status)
        if r.get("paper_kpa") is not None:
            papers.append((i, r["paper_kpa"] / truth))
    low, high = min(spans), max(spans)
    pad = 0.1 * (high - low)
    low, high = low - pad, high + pad
    for i, ratio in papers:
        inside = low <= ratio <= high
        marker = "x" if inside else ("^" if ratio > high else "v")
        ax.plot([i + 0.15], [min(max(ratio, low), high)], marker, ms=5, color="tab:red")
    ax.set_ylim(low, high)
    ax.legend(handles=_interval_legend(shown, bool(papers)), fontsize=9, ncol=2,
              loc="upper center", bbox_to_anchor=(0.5, -0.14))  # fmt: skip
    _sample_ticks(ax, rows)
    ax.set_ylabel("estimate / true modulus (95 % interval)", fontsize=10)
    ax.set_title(title, fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=120, bbox_inches="tight")  # the legend below the axes, whole
    plt.close(fig)
    return path


def _joint_bar(ax: Any, i: int, r: dict[str, Any], truth: float, colour: str) -> list[float]:
    """One trial's joint estimate with its interval, relative to the truth; the values drawn."""
    est = r["joint_kpa"] / truth
    lo, hi = r.get("joint_ci_kpa") or (None, None)
    if lo is None or hi is None:
        ax.plot([i - 0.1], [est], "o", ms=4, color=colour)
        return [est]
    yerr = [[est - lo / truth], [hi / truth - est]]
    ax.errorbar([i - 0.1], [est], yerr=yerr, fmt="o", ms=4, color=colour, capsize=2)
    return [est, lo / truth, hi / truth]


def _interval_legend(shown: set[str], papers: bool) -> list[Line2D]:
    """The legend of what the figure draws, and only that."""
    handles = [Line2D([], [], color="k", lw=1, label="true modulus (the simulated world's)")]
    if "reference" in shown:
        text = "the sample's reference measurement (drawn with its error)"
        handles.append(Line2D([], [], color="0.5", lw=1, ls="--", label=text))
    handles += [
        Line2D([], [], marker="o", ls="", color=c, label=f"joint fit, verdict {s}")
        for s, c in STATUS_COLOURS.items()
        if s in shown
    ]
    if papers:
        text = "paper's single point (Eqs. 13-14; ^ v: beyond the axis)"
        handles.append(Line2D([], [], marker="x", ls="", color="tab:red", label=text))
    return handles


def _sample_ticks(ax: Any, rows: Sequence[dict[str, Any]]) -> None:
    """One tick per sample at the middle of its trials, thin lines between samples."""
    groups: dict[str, list[int]] = {}
    for i, r in enumerate(rows):
        groups.setdefault(str(r.get("sample")), []).append(i)
    centres = [0.5 * (members[0] + members[-1]) for members in groups.values()]
    ax.set_xticks(centres, list(groups), fontsize=9, rotation=45 if len(groups) > 12 else 0)
    for members in list(groups.values())[1:]:
        ax.axvline(members[0] - 0.5, color="0.85", lw=0.8)
    ax.set_xlim(-0.6, len(rows) - 0.4)
    ax.set_xlabel("trials, grouped by sample", fontsize=10)
    ax.tick_params(axis="y", labelsize=9)


def fit_figures(outcomes: Sequence[Any], out_dir: Path, name: str) -> list[str]:
    """``palpate sim``'s figures of the fit: every trial's estimate with its interval
    (``intervals.png``) and the first trial with a joint fit drawn from its log (``fit.png``)."""
    rows = [o.as_dict() for o in outcomes if o.calibration is None]
    title = f"{name}: each trial's estimate, its 95 % interval and verdict"
    figures = [str(estimates_with_intervals(rows, out_dir / "intervals.png", title))]
    for o in outcomes:
        if o.log_path is None or o.joint is None or o.joint.modulus is None:
            continue
        figures.append(str(record_fit(read_log(o.log_path), out_dir / "fit.png")))
        break
    return figures
