"""What ``palpate design`` reports: the proposed sensor, its checks' margins and the simulated
check on phantoms across the range, as JSON or as text."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from palpate.campaigns.designcheck import (
    METHODS,
    UNITS,
    SimulatedWindow,
    error_summary,
    relative_error,
)
from palpate.sensor_design import DesignConstraints, DesignEvaluation, DesignResult
from palpate.simulation.trial import TrialOutcome


@dataclass(frozen=True)
class CheckRun:
    """The simulated check as run: its trials (none when skipped), wall time, the unit the
    moduli are shown in, the executor named and the lengths whose trials pass."""

    outcomes: list[TrialOutcome]
    wall: float
    unit: str
    executor: str
    window: SimulatedWindow | None = None


def design_dict(result: DesignResult, unit_name: str) -> dict[str, Any] | None:
    ev = result.evaluation
    if ev is None:
        return None
    d = ev.design
    unit = UNITS[unit_name]
    return {
        "fiber_radius_um": d.fiber_radius * 1e6,
        "wire_count": d.wire_count,
        "wire_diameter_um": d.wire_radius * 2e6,
        "tip_radius_mm": d.tip_radius * 1e3,
        "exposed_length_mm": d.exposed_length * 1e3,
        "length_window_mm": (
            None if result.length_window is None else [v * 1e3 for v in result.length_window]
        ),
        "critical_load_mn": ev.critical_load * 1e3,
        f"modulus_range_{unit_name.lower()}": [e / unit for e in ev.modulus_range],
        "delta_at_min_modulus_mm": ev.delta_soft * 1e3,
        "delta_at_max_modulus_mm": ev.delta_stiff * 1e3,
        "depth_ratio_at_min_modulus": ev.depth_ratio,
        "layer_strain_at_min_modulus": None if math.isnan(ev.contact_ratio) else ev.contact_ratio,
        "delta_bias_um": ev.delta_bias * 1e6,
        "detector_threshold_ue": None if ev.threshold is None else ev.threshold * 1e6,
        "peak_fiber_strain_ue": ev.peak_strain * 1e6,
        "checks": [
            {
                "name": c.name,
                "description": c.description,
                "value": c.value,
                "limit": c.limit,
                "margin": c.margin,
                "ok": c.ok,
            }
            for c in ev.checks
        ],
    }


def payload(
    result: DesignResult,
    constraints: DesignConstraints,
    run: CheckRun,
) -> dict[str, Any]:
    """What ``palpate design --json`` prints."""
    outcomes = run.outcomes
    return {
        "success": result.success,
        "message": result.message,
        "candidates": result.candidates,
        "feasible": result.feasible,
        "failures": result.failures,
        "encoder_resolution_um": constraints.encoder_resolution * 1e6,
        "design": design_dict(result, run.unit),
        "campaign": None
        if not outcomes
        else {
            "executor": run.executor,
            "trials": [
                {
                    **o.as_dict(),
                    **{f"relative_error_{m}": relative_error(o, m) for m in METHODS},
                }
                for o in outcomes
            ],
            **{m: error_summary(outcomes, m) for m in METHODS},
            **({} if run.window is None else run.window.as_dict()),
            "wall_s": run.wall,
        },
    }


def print_report(result: DesignResult, constraints: DesignConstraints, run: CheckRun) -> None:
    """What ``palpate design`` prints: the design, its checks and the simulated check."""
    print(("design: " if result.success else "NO DESIGN: ") + result.message)
    ev = result.evaluation
    if ev is None:
        return
    print()
    for k, v in _design_rows(result, ev, constraints, run.unit):
        print(f"  {k:<20} {v}")
    print()
    print(f"  {'check':<13} {'value':>10} {'limit':>10} {'margin':>7}  ok")
    for c in ev.checks:
        print(
            f"  {c.name:<13} {c.value:>10.4g} {c.limit:>10.4g} {c.margin:>7.2f}  "
            f"{'yes' if c.ok else 'NO'}"
        )
    if run.outcomes:
        print()
        _print_campaign(run)


def _design_rows(
    result: DesignResult, ev: DesignEvaluation, constraints: DesignConstraints, unit_name: str
) -> list[tuple[str, str]]:
    """(label, value) of the proposed sensor and its predicted indentations."""
    unit = UNITS[unit_name]
    d = ev.design
    lo, hi = ev.modulus_range
    counts = ev.delta_stiff / constraints.encoder_resolution
    wires = (
        "none (bare fiber)" if d.wire_count == 0 else f"{d.wire_count} x {d.wire_radius * 2e6:g} um"
    )
    window = (
        "fails: see the checks"
        if result.length_window is None
        else "all checks pass for "
        f"{result.length_window[0] * 1e3:.1f}-{result.length_window[1] * 1e3:.1f} mm"
    )
    return [
        ("fiber radius", f"{d.fiber_radius * 1e6:g} um"),
        ("NiTi wires", wires),
        ("tip radius", f"{d.tip_radius * 1e3:g} mm"),
        ("exposed length", f"{d.exposed_length * 1e3:.1f} mm ({window})"),
        ("P_cr", f"{ev.critical_load * 1e3:.3g} mN"),
        (
            f"delta at {lo / unit:g} {unit_name}",
            f"{ev.delta_soft * 1e3:.3f} mm (delta/R {ev.depth_ratio:.3f}, delta/h "
            f"{ev.contact_ratio:.3f})",
        ),
        (
            f"delta at {hi / unit:g} {unit_name}",
            f"{ev.delta_stiff * 1e3:.3f} mm ({counts:.0f} counts)",
        ),
        ("delta bias", f"{ev.delta_bias * 1e6:.1f} um (compression, detection, bow)"),
        (
            "detector threshold",
            "-" if ev.threshold is None else f"{ev.threshold * 1e6:.1f} ue (strain norm)",
        ),
    ]


def _print_campaign(run: CheckRun) -> None:
    outcomes, unit = run.outcomes, UNITS[run.unit]
    print(f"simulated bench campaign with the proposed sensor ({run.executor} executor):")
    head = f"  {'trial':<34} {'true':>8}"
    for m in METHODS:
        head += f" {m:>8} {'rel.err':>8}"
    print(head + "  state")
    for o in outcomes:
        line = f"  {o.spec.trial_id:<34} {o.spec.modulus / unit:>8.3f}"
        for m in METHODS:
            value, err = o.modulus(m), relative_error(o, m)
            line += " " + ("-" if value is None else f"{value / unit:.3f}").rjust(8)
            line += " " + ("-" if err is None else f"{100 * err:+.1f}%").rjust(8)
        print(f"{line}  {o.state}{'' if o.state == 'done' else ': ' + o.reason}")
    for m in METHODS:
        summary = error_summary(outcomes, m)
        mare, worst = summary["median_abs_relative_error"], summary["max_abs_relative_error"]
        if mare is not None and worst is not None:
            print(f"  {m}: median |relative error| {100 * mare:.1f} %, worst {100 * worst:.1f} %")
    print(f"  {len(outcomes)} trials in {run.wall:.1f} s wall; moduli in {run.unit}")
    if run.window is not None:
        print(f"  {window_text(run.window)}")


def window_text(window: SimulatedWindow) -> str:
    """The lengths whose simulated trials pass, and what failed at the others."""
    failed = "; ".join(f"at {v * 1e3:.1f} mm {why}" for v, why in window.failed)
    if window.lengths is None:
        return f"no length passes: {failed}"
    lo, hi = window.lengths
    return f"every phantom within tolerance at {lo * 1e3:.1f}-{hi * 1e3:.1f} mm" + (
        f" (beyond it: {failed})" if failed else ""
    )
