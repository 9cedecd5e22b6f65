"""``palpate sim --compare-methods``: the paper's single-point estimate vs the joint fit.

Both methods run on the same simulated trials (same seeds, same records). The contact error is
a fixed signed offset added to the contact mark the estimators are given (+ = the contact event
came late), 0, +-0.1 and +-0.3 mm by default, on top of the scene's own contact noise
(``contact_uncertainty_mm``). It changes only the estimate, not the motion (the state machine
still switches to the indentation speed at the simulated event), so each trial runs once and
every contact error re-estimates it. The paper's estimate uses the mark (delta = X_b - X_c,
Eq. 14); the joint fit never reads it (it finds the contact in the record), so its row is the
same for every error, which is the point.

Per method and contact error: median and worst |relative error| of E over the trials, how many
trials' 95 % intervals hold the true modulus (the joint fit, over its trials with a number; the
paper's method has none), the trials whose verdict is not ``ok`` (``estimation.verdict``), and
the median wall time per trial
of the estimator (the joint fit's is measured inside each trial; the paper's here).
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Any

from palpate.config.optics import MM
from palpate.config.schema import StackConfig
from palpate.estimation.beam.section import Section
from palpate.estimation.trial.estimate import estimate_from_marks
from palpate.simulation.trial import TrialOutcome

CONTACT_ERRORS_MM: tuple[float, ...] = (0.0, 0.1, -0.1, 0.3, -0.3)


@dataclass(frozen=True)
class MethodRow:
    """One line of the comparison (relative errors as fractions)."""

    method: str
    contact_error_mm: float
    trials: int
    estimates: int
    median_abs_rel_err: float | None
    worst_abs_rel_err: float | None
    worst_valid_abs_rel_err: float | None
    coverage: float | None
    flagged: int
    ms_per_trial: float | None


def _row(
    method: str,
    error_mm: float,
    outcomes: Sequence[TrialOutcome],
    moduli: Sequence[float | None],
    flagged: Sequence[bool],
    covered: Sequence[bool] | None,
    seconds: Sequence[float],
) -> MethodRow:
    errs = [
        abs(m - o.spec.modulus) / o.spec.modulus for o, m in zip(outcomes, moduli, strict=True) if m
    ]
    valid = [
        abs(m - o.spec.modulus) / o.spec.modulus
        for o, m, f in zip(outcomes, moduli, flagged, strict=True)
        if m and not f
    ]
    return MethodRow(
        method=method,
        contact_error_mm=error_mm,
        trials=len(outcomes),
        estimates=len(errs),
        median_abs_rel_err=statistics.median(errs) if errs else None,
        worst_abs_rel_err=max(errs) if errs else None,
        worst_valid_abs_rel_err=max(valid) if valid else None,
        coverage=None if covered is None or not covered else sum(covered) / len(covered),
        flagged=sum(flagged),
        ms_per_trial=1e3 * statistics.median(seconds) if seconds else None,
    )


def compare_methods(
    outcomes: Sequence[TrialOutcome],
    stack: StackConfig,
    section: Section,
    contact_errors_mm: Sequence[float] = CONTACT_ERRORS_MM,
) -> list[MethodRow]:
    """The comparison table's rows: for each contact error, the paper's method then the joint
    fit. Trials without marks (no buckling) count as failed estimates."""
    rows: list[MethodRow] = []
    fits = [o.joint for o in outcomes]
    joint_moduli = [o.modulus("joint") for o in outcomes]  # None when the verdict is none
    joint_flagged = [o.status != "ok" for o in outcomes]  # suspect: not counted as valid
    covered = [  # over the trials with a number (ok and suspect)
        f.covers(o.spec.modulus)
        for o, f, m in zip(outcomes, fits, joint_moduli, strict=True)
        if m is not None and f is not None
    ]
    joint_seconds = [o.joint_seconds for o in outcomes if o.joint_seconds is not None]
    for error_mm in contact_errors_mm:
        paper: list[float | None] = []
        seconds: list[float] = []
        for o in outcomes:
            m = o.marks
            if m is None or m.x_contact is None or o.exposed_length_at_buckling is None:
                paper.append(None)
                continue
            t0 = time.perf_counter()
            est = estimate_from_marks(
                m.x_contact + error_mm * MM,
                m.x_buckling,
                m.strains_at_buckling,
                o.exposed_length_at_buckling,
                stack,
                section,
                o.spec.poisson,
            )
            seconds.append(time.perf_counter() - t0)
            paper.append(None if est is None else est.modulus)
        rows.append(_row("paper", error_mm, outcomes, paper, [False] * len(paper), None, seconds))
        rows.append(
            _row("joint", error_mm, outcomes, joint_moduli, joint_flagged, covered, joint_seconds)
        )
    return rows


def comparison_payload(rows: Sequence[MethodRow], scene: str, seed: int) -> dict[str, Any]:
    return {
        "scene": scene,
        "seed": seed,
        "contact_error": "fixed signed offset (mm) added to the estimators' contact mark; "
        "+ = late; on top of the scene's contact_uncertainty_mm",
        "rows": [asdict(r) for r in rows],
    }


def print_comparison(rows: Sequence[MethodRow], scene: str) -> None:
    """The table as the README shows it."""

    def pct(v: float | None) -> str:
        return "-" if v is None else f"{100 * v:.1f}%"

    print(
        f"{scene} campaign: paper (Eqs. 13-14, contact event + buckling instant) vs joint fit "
        "(E and contact fitted on the whole record); contact error = signed offset on the "
        "contact mark"
    )
    cols = [("method", 6), ("contact err", 11), ("estimates", 9), ("median|err|", 11)]
    cols += [("worst|err|", 10), ("worst valid", 11), ("95% CI cover", 12), ("ms/trial", 8)]
    head = " ".join(f"{c:>{w}}" for c, w in cols)
    print(head)
    print("-" * len(head))
    for r in rows:
        cover = "-" if r.coverage is None else f"{100 * r.coverage:.0f}%"
        ms = "-" if r.ms_per_trial is None else f"{r.ms_per_trial:.1f}"
        print(
            f"{r.method:>6} {r.contact_error_mm:>+8.1f} mm {r.estimates:>4}/{r.trials:<4} "
            f"{pct(r.median_abs_rel_err):>11} {pct(r.worst_abs_rel_err):>10} "
            f"{pct(r.worst_valid_abs_rel_err):>11} {cover:>12} {ms:>8}"
        )
    print(
        "worst valid: over trials whose verdict is ok (the paper's: all); the joint fit "
        "ignores the contact mark, so its rows repeat"
    )
