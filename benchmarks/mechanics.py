"""Mechanics: speed against error of the elastica solvers, and the paper sensor's numbers.

Methods, on a log grid of e/L from 1e-8 to the branch end (paper sensor, L = 42 mm, gratings
3 mm long centred 10, 18, 26 mm from the tip):

* accurate: closed form; its error is measured against a DOP853 re-integration (rtol 1e-13) of
  its own initial-value problem (clamp curvature, p, r), an independent check of the curvatures;
* fast: Chebyshev surrogate, error against accurate; timed per query alone and in a 10,000 batch;
* shooting: the paper's method (Eqs. 8-11) at tight tolerances (rtol 1e-10) and at solve_ivp's
  defaults (rtol 1e-3, atol 1e-6), error against accurate, failures counted.

Errors: p relative to max(|p|, 1) (p reaches 0 at the branch end); curvature relative.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from benchmarks.report import BenchContext, BenchSection, Table, median_time
from palpate.config.optics import MM
from palpate.config.schema import SensorConfig
from palpate.estimation.beam.elastica import E_OVER_L_MAX, accurate, fast, shooting
from palpate.estimation.beam.elastica._scipy import solve_ivp
from palpate.estimation.beam.model import Beam
from palpate.estimation.beam.section import sensor_section
from palpate.estimation.fits.strain_fit import fit_strains

FloatArray = NDArray[np.float64]
L_PAPER = 0.042
DISTANCES = (0.010, 0.018, 0.026)  # grating centres from the sensor tip (m)
GRATING = 0.003
S0 = np.array([1.0 - (d + GRATING / 2) / L_PAPER for d in DISTANCES])
S1 = np.array([1.0 - (d - GRATING / 2) / L_PAPER for d in DISTANCES])


@dataclass
class Row:
    method: str
    time: float  # s per query
    err_p: float
    err_curv: float
    failures: int
    states: int


def _grid(n: int) -> FloatArray:
    return np.asarray(np.logspace(-8, math.log10(E_OVER_L_MAX), n))


def _rel(a: FloatArray, b: FloatArray, floor: float = 0.0) -> float:
    ok = np.isfinite(a)
    if not np.any(ok):
        return math.nan
    return float(np.max(np.abs(a[ok] - b[ok]) / np.maximum(np.abs(b[ok]), floor)))


def _reintegrated_means(e: float) -> FloatArray:
    """Grating means by DOP853 on theta'' = -p sin - r cos theta from accurate's clamp state."""
    sol = accurate.solve(e)
    p, r = float(sol.p), float(sol.r)

    def rhs(_s: float, y: FloatArray) -> list[float]:
        return [y[1], -p * math.sin(y[0]) - r * math.cos(y[0])]

    y0 = [0.0, float(sol.curvature(0.0))]
    ivp = solve_ivp(rhs, (0.0, 1.0), y0, method="DOP853", rtol=1e-13, atol=1e-18, dense_output=True)
    theta0, theta1 = ivp.sol(S0)[0], ivp.sol(S1)[0]
    return np.asarray((theta1 - theta0) / (S1 - S0))


def _accurate_row(grid: FloatArray, repeats: int) -> Row:
    ref = accurate.solve(grid[:, None])
    means = ref.mean_curvature(S0, S1)
    ivp = np.array([_reintegrated_means(float(e)) for e in grid])
    picks = grid[:: max(1, len(grid) // 4)]
    t = float(np.median([median_time(_query(accurate.solve, float(e)), repeats) for e in picks]))
    return Row("accurate", t, math.nan, _rel(means, ivp), 0, grid.size)


def _query(solver: Callable[[Any], Any], e: float) -> Callable[[], Any]:
    return lambda: solver(e).mean_curvature(S0, S1)


def _fast_rows(grid: FloatArray, ref: Any, ref_means: FloatArray, ctx: BenchContext) -> list[Row]:
    sol = fast.solve(grid[:, None])
    err_p = _rel(sol.p[:, 0], ref.p[:, 0], floor=1.0)
    err_c = _rel(sol.mean_curvature(S0, S1), ref_means)
    single = median_time(_query(fast.solve, 1e-3), ctx.repeats, number=50)
    rng = np.random.default_rng(ctx.seed)
    batch = rng.uniform(0.0, E_OVER_L_MAX, 10_000)[:, None]
    per_query = median_time(lambda: fast.solve(batch).mean_curvature(S0, S1), ctx.repeats) / 1e4
    return [
        Row("fast (one query)", single, err_p, err_c, 0, grid.size),
        Row("fast (10k batch)", per_query, err_p, err_c, 0, grid.size),
    ]


def _shooting_row(
    name: str, grid: FloatArray, opts: shooting.ShootingOptions, ref: Any, ref_means: FloatArray
) -> Row:
    times, p, means, failures = [], [], [], 0
    for e in grid:
        t0 = time.perf_counter()
        res = shooting.shoot(float(e), opts)
        times.append(time.perf_counter() - t0)
        failures += res.failures
        p.append(float(res.p))
        means.append(res.mean_curvature(S0, S1))
    sel = np.searchsorted(ref.e_over_L[:, 0], grid)
    return Row(
        name,
        float(np.median(times)),
        _rel(np.array(p), ref.p[sel, 0], floor=1.0),
        _rel(np.array(means), ref_means[sel]),
        failures,
        grid.size,
    )


def _pareto(rows: list[Row], path: Any) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    for row in rows:
        err = np.nanmax([row.err_p, row.err_curv])
        ax.loglog(row.time, max(err, 1e-16), "o")
        label = f"{row.method} ({row.failures} fail)" if row.failures else row.method
        ax.annotate(label, (row.time, max(err, 1e-16)), fontsize=8)
    ax.set_xlabel("time per query (s)")
    ax.set_ylabel("max relative error (p, grating curvature)")
    ax.set_title("Clamped-pinned elastica: speed against error")
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _sensor_table() -> Table:
    sec = sensor_section(SensorConfig())
    table = Table(
        "Paper sensor: section and buckling loads",
        ["L (mm)", "EI (N m^2)", "dy_fbg (mm)", "P_cr (N)", "P_peak (N)", "e_cr (um)"],
        note="Fiber r = 0.115 mm, 67 GPa on 4 NiTi wires r = 0.1 mm, 55 GPa (paper Sec. II).",
    )
    for length_mm in (42, 44, 46, 48, 50):
        beam = Beam.from_section(sec, length_mm * MM)
        table.rows.append(
            [
                length_mm,
                sec.EI,
                sec.fiber_offset * 1e3,
                beam.critical_load(),
                beam.peak_load(),
                beam.critical_shortening() * 1e6,
            ]
        )
    return table


def _beam_table(ctx: BenchContext) -> Table:
    beam = Beam.from_section(sensor_section(SensorConfig()), L_PAPER)
    rng = np.random.default_rng(ctx.seed)
    e = rng.uniform(0.0, 0.02 * L_PAPER, 10_000)
    iv = np.stack([S0 * L_PAPER, S1 * L_PAPER], axis=1)
    strains = beam.grating_strains(2e-3, iv)
    table = Table("Beam (SI) hot paths, paper sensor at 42 mm", ["call", "time per query (s)"])
    table.rows.append(
        ["force(e), 10k batch", median_time(lambda: beam.force(e), ctx.repeats) / 1e4]
    )
    table.rows.append(
        [
            "grating_strains(e), 10k batch x 3",
            median_time(lambda: beam.grating_strains(e, iv), ctx.repeats) / 1e4,
        ]
    )
    table.rows.append(
        ["fit_strains (3 gratings)", median_time(lambda: fit_strains(beam, strains, iv), 3)]
    )
    return table


def run(ctx: BenchContext) -> BenchSection:
    grid = _grid(10 if ctx.quick else 25)
    shoot_grid = _grid(4 if ctx.quick else 8)
    full = np.unique(np.concatenate([grid, shoot_grid]))
    fast.surrogate()  # build outside the timings
    ref = accurate.solve(full[:, None])
    ref_means = ref.mean_curvature(S0, S1)
    rows = [_accurate_row(grid, ctx.repeats)]
    rows += _fast_rows(full, ref, ref_means, ctx)
    tight = shooting.ShootingOptions()
    rows.append(_shooting_row("shooting (rtol 1e-10)", shoot_grid, tight, ref, ref_means))
    loose = shooting.ShootingOptions(rtol=1e-3, atol=1e-6)
    rows.append(_shooting_row("shooting (defaults)", shoot_grid, loose, ref, ref_means))
    t_shoot = rows[-2].time
    table = Table(
        "Elastica solvers: paper sensor (L = 42 mm, gratings at 10/18/26 mm), "
        f"e/L from 1e-8 to {E_OVER_L_MAX:.4f}",
        ["method", "time/query (s)", "speedup vs shooting", "err p", "err curv", "failures"],
        note=(
            "err p: max |dp| / max(|p|, 1) vs accurate; err curv: max relative error of the three "
            "grating-mean curvatures (accurate: vs DOP853 re-integration, rtol 1e-13). "
            "Shooting runs on a coarser grid; failures = states without a converged solution."
        ),
    )
    for row in rows:
        table.rows.append(
            [
                row.method,
                row.time,
                t_shoot / row.time,
                "ref" if math.isnan(row.err_p) else row.err_p,
                row.err_curv,
                f"{row.failures}/{row.states}",
            ]
        )
    ctx.out_dir.mkdir(parents=True, exist_ok=True)
    figure = ctx.out_dir / "mechanics_pareto.png"
    _pareto(rows, figure)
    return BenchSection(
        name="mechanics",
        tables=[table, _sensor_table(), _beam_table(ctx)],
        figures=[figure],
        summary={
            row.method: {
                "time_per_query_s": row.time,
                "err_p": row.err_p,
                "err_curvature": row.err_curv,
                "failures": row.failures,
                "states": row.states,
            }
            for row in rows
        },
    )
