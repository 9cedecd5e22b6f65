"""A campaign's per-sample table as ``palpate sim`` prints it, and its JSON fields in kPa."""

from __future__ import annotations

from collections.abc import Sequence

from palpate.campaigns.campaign import SampleRow
from palpate.reports import verdicts


def kpa_fields(d: dict[str, object]) -> dict[str, object]:
    """A sample summary's fields with its moduli (Pa) in kPa, their keys suffixed ``_kpa``."""
    out: dict[str, object] = {}
    for k, v in d.items():
        if k in ("actual", "mean", "median", "rmse", "iqr") and isinstance(v, float):
            out[f"{k}_kpa"] = v / 1e3
        else:
            out[k] = v
    return out


def print_table(name: str, rows: Sequence[SampleRow], tallies: dict[str, verdicts.Tally]) -> None:
    """The campaign's per-sample table (as the paper's Tables I and II), as a person reads it."""
    print(
        f"{name} campaign: estimated vs actual Young's modulus (kPa), joint fit (E and contact "
        "point fitted on the whole record; the paper's estimate is in --json) over the trials "
        "whose verdict is ok, outliers > 3 MPa removed; ok/sus/none: verdicts; cover: 95 % "
        "intervals holding the truth / trials with a number"
    )
    cols = [("sample", 8), ("trials", 6), ("ok/sus/none", 11), ("estimated", 10), ("actual", 9)]
    cols += [("RMSE", 9), ("IQR", 9), ("rel.err", 8), ("cover", 6)]
    head = " ".join(f"{c:>{w}}" for c, w in cols)
    print(head)
    print("-" * len(head))
    for r in rows:
        s = r.summary

        def k(v: float | None) -> str:
            return "-" if v is None else f"{v / 1e3:.2f}"

        rel = "-" if s.relative_error is None else f"{100 * s.relative_error:+.1f}%"
        t = tallies[r.sample]
        counts = verdicts.counts_column(t)
        print(
            f"{r.sample:>8} {r.trials:>6} {counts:>11} {k(s.mean):>10} {k(s.actual):>9} "
            f"{k(s.rmse):>9} {k(s.iqr):>9} {rel:>8} {f'{t.covered}/{t.numbers}':>6}"
        )
