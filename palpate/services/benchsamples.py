"""The bench session's per-sample rows (``palpate trial``'s ``samples.csv`` and ``--json``): as
the paper's Tables I and II, the joint fit over the trials whose verdict is ok, the paper's
estimate, the verdicts' tally and the sample's trials pooled (``palpate.campaigns.pooled``)::

    rows = bench_samples(outcomes, outlier_above=3e6)
"""

from __future__ import annotations

from typing import Any

from palpate.campaigns.pooled import pooled_by_sample, pooled_fields
from palpate.estimation.fits.stiffness import summarize
from palpate.estimation.verdict import STATUSES
from palpate.lab.trial import SKIPPED, BenchOutcome


def bench_samples(outcomes: list[BenchOutcome], outlier_above: float) -> list[dict[str, Any]]:
    """Per sample: the verdict counts and its trials pooled (one answer per sample); with a
    known modulus also mean, RMSE, IQR, relative error (Tables I/II) of the joint fit over the
    trials whose verdict is ok; without one the mean of those."""
    by_sample: dict[str, list[BenchOutcome]] = {}
    for o in outcomes:
        if o.state != SKIPPED and o.calibration is None:
            by_sample.setdefault(o.trial.sample, []).append(o)
    pooled = pooled_by_sample((o.trial.sample, o) for outs in by_sample.values() for o in outs)
    rows = []
    for name, outs in by_sample.items():
        reference = outs[0].trial.modulus
        counts: dict[str, int] = {v: sum(1 for o in outs if o.status == v) for v in STATUSES}
        if reference is None:
            ok = [m for o in outs if o.status == "ok" and (m := o.modulus()) is not None]
            rows.append(
                {
                    "sample": name,
                    "trials": len(outs),
                    **counts,
                    "reference_kpa": None,
                    "joint_mean_kpa": _pa_to_kpa(sum(ok) / len(ok)) if ok else None,
                    "count": len(ok),
                    **pooled_fields(pooled.get(name), None),
                }
            )
            continue
        kept = [o.modulus() if o.status == "ok" else None for o in outs]
        s = summarize(kept, reference, outlier_above)
        paper = summarize([_paper(o) for o in outs], reference, outlier_above)
        rows.append(
            {
                "sample": name,
                "trials": len(outs),
                **counts,
                "reference_kpa": reference / 1e3,
                "joint_mean_kpa": _pa_to_kpa(s.mean),
                "joint_rmse_kpa": _pa_to_kpa(s.rmse),
                "joint_iqr_kpa": _pa_to_kpa(s.iqr),
                "joint_relative_error": s.relative_error,
                "count": s.count,
                "outliers": s.outliers,
                "failed": s.failed,
                "paper_mean_kpa": _pa_to_kpa(paper.mean),
                "paper_relative_error": paper.relative_error,
                **pooled_fields(pooled.get(name), reference),
            }
        )
    return rows


def _paper(o: BenchOutcome) -> float | None:
    """The paper's single-point estimate (Pa), None without one."""
    return None if o.estimate is None else o.estimate.modulus


def _pa_to_kpa(v: float | None) -> float | None:
    return None if v is None else v / 1e3
