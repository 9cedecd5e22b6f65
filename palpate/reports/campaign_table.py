"""A campaign's per-sample table (as the paper's Tables I and II): as ``palpate sim`` prints
it, as ``samples.csv`` holds it, and its JSON fields in kPa.

Each sample's row gives the joint fit's statistics (over the trials whose verdict is ``ok``)
and, beside them, the paper's single-point estimate's (Eqs. 13-14) over the same sample's
trials, so neither is read for the other.
"""

from __future__ import annotations

import textwrap
from collections.abc import Iterable, Sequence
from typing import Any

from palpate.campaigns.campaign import SampleRow, summarize_campaign
from palpate.campaigns.pooled import pooled_by_sample, pooled_fields
from palpate.estimation.verdict import STATUSES
from palpate.reports import verdicts
from palpate.simulation.trial import TrialOutcome


def kpa_fields(d: dict[str, object]) -> dict[str, object]:
    """A sample summary's fields with its moduli (Pa) in kPa, their keys suffixed ``_kpa``."""
    out: dict[str, object] = {}
    for k, v in d.items():
        if k in ("against", "mean", "median", "rmse", "iqr") and isinstance(v, float):
            out[f"{k}_kpa"] = v / 1e3
        else:
            out[k] = v
    return out


def sample_records(
    outcomes: Sequence[TrialOutcome], joint: Iterable[SampleRow], outlier_above: float
) -> list[dict[str, Any]]:
    """One record per sample (``samples.csv``'s columns): the joint fit's row, the verdicts'
    tally and the paper's estimate over the same trials."""
    paper = {r.sample: r.summary for r in summarize_campaign(outcomes, outlier_above, "paper")}
    tallies = verdicts.by_sample(outcomes)
    pooled = pooled_by_sample((o.spec.sample, o) for o in outcomes)
    truth = {o.spec.sample: o.spec.modulus for o in outcomes}
    records = []
    for r in joint:
        s, p, t = r.summary, paper.get(r.sample), tallies.get(r.sample)
        counts: dict[str, int] = {} if t is None else {k: t.counts.get(k, 0) for k in STATUSES}
        records.append(
            {
                "sample": r.sample,
                "trials": r.trials,
                **counts,
                "joint_mean_kpa": _kpa(s.mean),
                "true_kpa": _kpa(s.against),
                "joint_rmse_kpa": _kpa(s.rmse),
                "joint_iqr_kpa": _kpa(s.iqr),
                "joint_relative_error": s.relative_error,
                "intervals_holding_truth": None if t is None else t.covered,
                "trials_with_number": None if t is None else t.numbers,
                "paper_mean_kpa": None if p is None else _kpa(p.mean),
                "paper_relative_error": None if p is None else p.relative_error,
                **pooled_fields(pooled.get(r.sample), truth.get(r.sample)),
            }
        )
    return records


def _kpa(v: float | None) -> float | None:
    return None if v is None else v / 1e3


TITLE = "{name} campaign: Young's modulus (kPa) per sample"
KEY = (
    "joint: the joint fit (E and contact fitted on the whole record) over the trials whose "
    "verdict is ok, outliers > 3 MPa removed; true: the simulated world's modulus, which errors "
    "are judged against; paper: the paper's single-point estimate (Eqs. 13-14) over the same "
    "sample's trials; ok/sus/none: verdicts; cover: 95 % intervals holding the true modulus / "
    "trials with a number; pooled: every trial of the sample fitted together (one modulus, "
    "each trial's own contact), with its interval and verdict (the pooled belief check); "
    "marked 'relaxed': the sample relaxes in its holds, the answer is its relaxed modulus "
    "(docs/viscoelastic.md)"
)


def print_table(name: str, records: Sequence[dict[str, Any]]) -> None:
    """The campaign's per-sample table (:func:`sample_records`), as a person reads it."""
    print(TITLE.format(name=name))
    print(textwrap.fill(KEY, width=100, initial_indent="  ", subsequent_indent="  "))
    cols = [("sample", 8), ("trials", 6), ("ok/sus/none", 11), ("joint", 10), ("true", 9)]
    cols += [("RMSE", 9), ("IQR", 9), ("rel.err", 8), ("cover", 6), ("paper", 9)]
    cols += [("rel.err", 8), ("pooled [95 % interval]", 26), ("verdict", 8)]
    head = " ".join(f"{c:>{w}}" for c, w in cols)
    print(head)
    print("-" * len(head))
    for r in records:
        counts = "/".join(str(r.get(k, 0)) for k in STATUSES)
        cover = f"{r['intervals_holding_truth']}/{r['trials_with_number']}"
        print(
            f"{r['sample']:>8} {r['trials']:>6} {counts:>11} {_cell(r['joint_mean_kpa']):>10} "
            f"{_cell(r['true_kpa']):>9} {_cell(r['joint_rmse_kpa']):>9} "
            f"{_cell(r['joint_iqr_kpa']):>9} {_pct(r['joint_relative_error']):>8} {cover:>6} "
            f"{_cell(r['paper_mean_kpa']):>9} {_pct(r['paper_relative_error']):>8} "
            f"{_pooled(r):>26} {r['pooled_verdict'] or '-':>8}"
        )
    for r in records:
        if r["pooled_reasons"]:
            print(f"{r['sample']}: pooled {r['pooled_verdict']}: {r['pooled_reasons']}")


def _pooled(r: dict[str, Any]) -> str:
    """The pooled estimate and its interval (kPa), or '-'."""
    if r["pooled_kpa"] is None:
        return "-"
    cell = f"{r['pooled_kpa']:.2f} [{r['pooled_ci_low_kpa']:.1f}, {r['pooled_ci_high_kpa']:.1f}]"
    return f"relaxed {cell}" if r.get("pooled_modulus") == "relaxed" else cell


def _cell(v: float | None) -> str:
    return "-" if v is None else f"{v:.2f}"


def _pct(v: float | None) -> str:
    return "-" if v is None else f"{100 * v:+.1f}%"
