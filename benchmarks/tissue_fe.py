"""The finite-element tissue against the closed forms: the numbers in docs/tissue-fe.md.

``python -m benchmarks.tissue_fe [--quick]`` prints markdown tables:

1. validation: Hertz (thick layer, small depth), Sneddon (thick layer, deep), Dimitriadis'
   first-order term (h = R/2, chi <= 0.5, bonded and sliding);
2. mesh convergence on the paper's phantom (R = 3.5 mm, h = 10 mm, 40 mm dish, nu = 0.45);
3. where the closed forms depart from the FE on that phantom and around it: thin layers, deep
   indentation, neo-Hookean stiffening, sliding base, nu;
4. the time to build a table (median of 3 solves) and to read one back (median of 21 reads).

Every FE number is F / (E R^2) or a ratio of forces; the closed forms are the estimator's own
(estimation.contact.hertz, estimation.contact.law) and today's world law (sim.tissue.TissueModel
with
Sneddon's sphere and the Dimitriadis series). Not part of ``palpate bench`` (minutes of solves).
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import sys
import time
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from benchmarks.report import BenchContext, BenchSection, Table
from palpate.estimation.contact.hertz import hertz_force
from palpate.estimation.contact.layer import dimitriadis_bracket, dimitriadis_coefficients
from palpate.sim.fem.law import curve_from_table
from palpate.sim.fem.problem import LayerProblem
from palpate.sim.fem.solver import solve_indentation
from palpate.sim.fem.table import read_table, save_table, solve_table
from palpate.sim.tissue import TissueModel

FloatArray = NDArray[np.float64]
PAPER = LayerProblem.from_dimensions(3.5e-3, 10e-3, 40e-3, poisson=0.45)
THICK = LayerProblem(thickness_ratio=200.0, radius_ratio=200.0, poisson=0.45)


def _row(cells: Sequence[object]) -> str:
    return "| " + " | ".join(f"{c:.4g}" if isinstance(c, float) else str(c) for c in cells) + " |"


def _table(header: Sequence[str], rows: Sequence[Sequence[object]]) -> list[str]:
    return [_row(header), _row(["---"] * len(header)), *(_row(r) for r in rows)]


def _solve(problem: LayerProblem) -> tuple[FloatArray, FloatArray, FloatArray]:
    res = solve_indentation(problem)
    if not res.success:
        print(f"<!-- {problem}: {res.message} -->")
    return res.depths, res.forces, res.contact_radii


def _hertz(problem: LayerProblem, x: FloatArray) -> FloatArray:
    return np.asarray(hertz_force(1.0, x, 1.0, problem.poisson))


def _world(problem: LayerProblem, x: FloatArray, *, layer: bool = True) -> FloatArray:
    """Today's world law (Sneddon sphere x Dimitriadis series), E = R = 1."""
    law = TissueModel(
        modulus=1.0,
        poisson=problem.poisson,
        thickness=problem.thickness_ratio,
        bonded=problem.base == "bonded",
        tip_radius=1.0,
        finite_thickness=layer,
        large_indentation=True,
    )
    return law.force(x)


def validation() -> list[str]:
    out = ["### Validation", "", *_thick_layer_lines()]
    out += [
        "",
        "Thin layer h = R/2, L = 20 h, chi = sqrt(R delta)/h <= 0.5: k1 FE fitted to"
        " F/F_Hertz - 1 = k1 chi + k2 chi^2 + k3 chi^3; series = Dimitriadis' quartic:",
        "",
    ]
    header = ["base", "nu", "k1 FE", "k1 Dimitriadis"]
    header += ["FE/series chi=0.2", "FE/series chi=0.5", "FE/(1+k1 chi) chi=0.5"]
    return out + _table(header, _thin_layer_rows())


def _thick_layer_lines() -> list[str]:
    """A thick layer against Hertz at small depth and Sneddon's exact sphere deep."""
    out = []
    p = dataclasses.replace(THICK, depth_max=0.01, n_depths=4)
    x, f, a = _solve(p)
    out += ["Thick layer (h = L = 200 R), nu = 0.45, small depth:", ""]
    out += _table(
        ["delta/R", "F/F_Hertz", "a/sqrt(R delta)"],
        [
            (float(d), float(r), float(c))
            for d, r, c in zip(x, f / _hertz(p, x), a / np.sqrt(x), strict=True)
        ],
    )
    p = dataclasses.replace(THICK, depth_max=1.0, n_depths=8)
    x, f, a = _solve(p)
    sneddon = _world(p, x, layer=False)
    out += ["", "Thick layer, deep (Sneddon's exact sphere on a half-space):", ""]
    out += _table(
        ["delta/R", "F/F_Sneddon", "F/F_Hertz"],
        [
            (float(d), float(r), float(h))
            for d, r, h in zip(x, f / sneddon, f / _hertz(p, x), strict=True)
        ],
    )
    return out


def _thin_layer_rows() -> list[tuple[object, ...]]:
    """Per base and nu: the FE's first-order coefficient and its ratio to Dimitriadis' series."""
    rows: list[tuple[object, ...]] = []
    for base in ("bonded", "sliding"):
        for nu in (0.0, 0.3, 0.45, 0.5):
            prob = LayerProblem(
                thickness_ratio=0.5,
                radius_ratio=10.0,
                poisson=nu,
                base=base,
                depth_max=0.0625,
                n_depths=10,
            )
            x, f, _ = _solve(prob)
            chi = np.sqrt(x) / 0.5
            ratio = f / _hertz(prob, x)
            coef = np.linalg.lstsq(
                np.stack([chi, chi**2, chi**3], axis=1), ratio - 1.0, rcond=None
            )[0]
            k = dimitriadis_coefficients(nu, bonded=base == "bonded")
            series = dimitriadis_bracket(chi, k)[0]
            i2 = int(np.argmin(np.abs(chi - 0.2)))
            rows.append(
                (
                    base,
                    nu,
                    float(coef[0]),
                    k[0],
                    float(ratio[i2] / series[i2]),
                    float(ratio[-1] / series[-1]),
                    float(ratio[-1] / (1 + k[0] * chi[-1])),
                )
            )
    return rows


def convergence(resolutions: Sequence[int]) -> list[str]:
    out = ["### Mesh convergence (paper phantom, bonded, frictionless)", ""]
    for material in ("linear", "neo-hookean"):
        rows: list[tuple[object, ...]] = []
        previous = None
        for res in resolutions:
            prob = dataclasses.replace(PAPER, material=material, n_depths=4, resolution=res)
            start = time.perf_counter()
            result = solve_indentation(prob)
            seconds = time.perf_counter() - start
            change = (
                "" if previous is None else f"{np.max(np.abs(result.forces / previous - 1)):.2e}"
            )
            rows.append(
                (
                    res,
                    result.n_elements,
                    *[float(v) for v in result.forces],
                    change,
                    f"{seconds:.1f}",
                )
            )
            previous = result.forces
        depths = [f"F/(ER^2) at {d:.4g}" for d in dataclasses.replace(PAPER, n_depths=4).depths()]
        out += [f"{material}:", ""]
        out += _table(["resolution", "triangles", *depths, "max change", "s"], rows)
        out.append("")
    return out


def departures() -> list[str]:
    out = ["### The closed forms against the FE", ""]
    cases = {
        "paper, linear": PAPER,
        "paper, neo-Hookean": dataclasses.replace(PAPER, material="neo-hookean"),
        "paper, linear, sliding base": dataclasses.replace(PAPER, base="sliding"),
        "paper, linear, full stick": dataclasses.replace(PAPER, contact="stick"),
        "h = 3 mm, linear": LayerProblem.from_dimensions(3.5e-3, 3e-3, 40e-3, poisson=0.45),
        "h = 3 mm, neo-Hookean": LayerProblem.from_dimensions(
            3.5e-3, 3e-3, 40e-3, poisson=0.45, material="neo-hookean"
        ),
        "h = 20 mm, linear": LayerProblem.from_dimensions(3.5e-3, 20e-3, 40e-3, poisson=0.45),
    }
    picks = [0.01, 0.09, 0.25, 0.49, 0.7225, 1.0]
    for name, prob in cases.items():
        x, f, _ = _solve(prob)
        keep = [i for i, d in enumerate(x) if any(abs(d - q) < 1e-9 for q in picks)]
        x, f = x[keep], f[keep]
        rows: list[tuple[object, ...]] = [
            (float(d), float(fe), float(fe / h), float(fe / s), float(fe / w))
            for d, fe, h, s, w in zip(
                x, f, _hertz(prob, x), _world(prob, x, layer=False), _world(prob, x), strict=True
            )
        ]
        out += [f"{name} (h/R = {prob.thickness_ratio:.4g}):", ""]
        out += _table(
            ["delta/R", "F/(E R^2)", "FE/Hertz", "FE/Sneddon", "FE/(Sneddon x Dimitriadis)"], rows
        )
        out.append("")
    out += ["nu dependence (paper geometry, linear, bonded), FE/(Sneddon x Dimitriadis):", ""]
    rows = []
    for nu in (0.40, 0.45, 0.49, 0.5):
        prob = dataclasses.replace(PAPER, poisson=nu)
        x, f, _ = _solve(prob)
        ratio = f / _world(prob, x)
        rows.append(
            (nu, *[float(ratio[np.argmin(np.abs(x - q))]) for q in (0.09, 0.25, 0.49, 1.0)])
        )
    out += _table(["nu", "0.09", "0.25", "0.49", "1.0"], rows)
    return out


def timings(directory: str) -> list[str]:
    from pathlib import Path

    out = ["### Build and read-back times", ""]
    rows: list[tuple[object, ...]] = []
    for material in ("linear", "neo-hookean"):
        prob = dataclasses.replace(PAPER, material=material)
        builds = []
        for _ in range(3):
            table = solve_table(prob)
            builds.append(table.build_seconds)
        save_table(table, Path(directory))
        reads = []
        for _ in range(21):
            start = time.perf_counter()
            curve_from_table(read_table(prob, Path(directory)))  # type: ignore[arg-type]
            reads.append(time.perf_counter() - start)
        rows.append(
            (material, f"{statistics.median(builds):.1f}", f"{1e3 * statistics.median(reads):.2f}")
        )
    out += _table(
        ["material", "build s (median of 3)", "read + interpolant ms (median of 21)"], rows
    )
    return out


def _markdown_tables(lines: list[str]) -> list[Table]:
    """The markdown tables of a section as ``Table``s, each titled by the text before it."""
    tables: list[Table] = []
    title = ""
    rows: list[list[str]] = []
    for line in [*lines, ""]:
        if line.startswith("|"):
            cells = [c.strip() for c in line.strip("|").split("|")]
            if not set("".join(cells)) <= {"-"}:
                rows.append(cells)
            continue
        if rows:
            tables.append(Table(title=title, columns=rows[0], rows=list(rows[1:])))
            rows = []
        if line.strip():
            title = line.strip("#: ").strip()
    return tables


def run(ctx: BenchContext) -> BenchSection:
    """``palpate bench`` section: the FE against Hertz, Sneddon and Dimitriadis, its build and
    read times (``--quick``), and the mesh convergence and departures of the closed forms."""
    import tempfile

    with tempfile.TemporaryDirectory(prefix="palpate-fe-") as tmp:
        lines = validation() + timings(tmp)
    if not ctx.quick:
        lines += convergence((3, 4, 6, 8, 12)) + departures()
    return BenchSection(name="tissue-fe", tables=_markdown_tables(lines))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.tissue_fe")
    parser.add_argument(
        "--section", choices=["validation", "convergence", "departures", "timings"], action="append"
    )
    parser.add_argument("--tmp", default="/tmp/palpate-fe-timing")
    args = parser.parse_args(argv)
    sections = args.section or ["validation", "convergence", "departures", "timings"]
    for name in sections:
        start = time.perf_counter()
        if name == "validation":
            lines = validation()
        elif name == "convergence":
            lines = convergence((3, 4, 6, 8, 12))
        elif name == "departures":
            lines = departures()
        else:
            lines = timings(args.tmp)
        print(
            "\n".join(lines),
            f"\n<!-- {name}: {time.perf_counter() - start:.0f} s -->\n",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
