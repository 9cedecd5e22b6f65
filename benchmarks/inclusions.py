"""The three-dimensional inclusion world: its validation and what a palpation can see.

``python -m benchmarks.inclusions [--section NAME]`` prints the markdown tables of
docs/inclusions.md (tens of minutes the first time: every geometry is a 3-D solve; the tables
are cached, so a second run reads them):

- ``validation``: the 3-D solve without inclusions against the axisymmetric world, with an
  inclusion on the axis against the axisymmetric solve holding it, mesh convergence, the far
  field;
- ``visibility``: the apparent modulus (the force at the depth a trial reaches, over the
  homogeneous layer's) against the inclusion's lateral offset and depth, for the paper's sensor
  and for the lung sensor;
- ``limits``: the deepest centre depth at which an inclusion straight below the tip is still
  seen above the noise floor, by size and contrast, for both sensors;
- ``published``: Egorov and Sarvazyan's phantoms (IEEE TMI 27:1275, 2008, Table II: a 5 kPa
  layer 35 mm thick, inclusions 5-18 mm across at 10 mm depth, 10-156 kPa) under the lung
  sensor.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from palpate.sim.fem import load_table
from palpate.sim.fem.solver import solve_indentation
from palpate.sim.fem3d import Inclusion, InclusionProblem, RatioTable, load_ratios

FloatArray = NDArray[np.float64]


@dataclasses.dataclass(frozen=True)
class Sensor:
    """A sensor on its sample: tip radius, layer, the matrix's modulus and the buckling load
    (the force a trial's tip holds once the beam buckles: where the trial stops pressing)."""

    name: str
    tip_mm: float
    thickness_mm: float
    lateral_mm: float
    matrix_kpa: float
    buckling_n: float
    inclusion_radius_mm: float
    depths_mm: tuple[float, ...]
    offsets_mm: tuple[float, ...]

    def problem(self, inclusions: tuple[Inclusion, ...] = ()) -> InclusionProblem:
        r = self.tip_mm
        return InclusionProblem(
            thickness_ratio=self.thickness_mm / r,
            radius_ratio=self.lateral_mm / r,
            poisson=0.45,
            inclusions=inclusions,
        )

    def inclusion(self, offset_mm: float, depth_mm: float, contrast: float) -> Inclusion:
        r = self.tip_mm
        return Inclusion(offset_mm / r, 0.0, depth_mm / r, self.inclusion_radius_mm / r, contrast)

    def end_depth(self) -> float:
        """delta / R at which the homogeneous layer pushes back with the buckling load."""
        table = load_table(self.problem().layer())
        scale = self.matrix_kpa * 1e3 * (self.tip_mm * 1e-3) ** 2
        return float(np.interp(self.buckling_n / scale, table.forces, table.depths))


PAPER = Sensor("paper (R 3.5 mm, S8 314.5 kPa, 10 mm layer)", 3.5, 10.0, 40.0, 314.53, 1.35,
               2.5, (3.5, 5.0, 7.0), (0.0, 3.5, 7.0, 14.0))  # fmt: skip
LUNG = Sensor("lung (R 10 mm, 2 kPa, 20 mm layer)", 10.0, 20.0, 60.0, 2.0, 0.0197,
              5.0, (7.5, 10.0, 14.0), (0.0, 5.0, 10.0, 20.0))  # fmt: skip
CONTRASTS = (5.0,)


def _row(cells: Sequence[object]) -> str:
    return "| " + " | ".join(f"{c:.4g}" if isinstance(c, float) else str(c) for c in cells) + " |"


def _table(header: Sequence[str], rows: Sequence[Sequence[object]]) -> list[str]:
    return [_row(header), _row(["---"] * len(header)), *(_row(r) for r in rows)]


def _at(table: RatioTable, depth: float) -> float:
    return float(np.interp(depth, table.depths, table.ratios))


def visibility(sensors: Sequence[Sensor] = (PAPER, LUNG)) -> list[str]:
    out = ["### Apparent modulus over the matrix's, at the depth a trial reaches", ""]
    for sensor in sensors:
        end = sensor.end_depth()
        out += [
            f"{sensor.name}; inclusion radius {sensor.inclusion_radius_mm:g} mm; trial depth "
            f"delta/R = {end:.3f}; rows: centre depth, columns: lateral offset (mm):",
            "",
        ]
        for contrast in CONTRASTS:
            rows = []
            for depth in sensor.depths_mm:
                cells: list[object] = [f"{contrast:g}x, {depth:g} mm"]
                for offset in sensor.offsets_mm:
                    inc = sensor.inclusion(offset, depth, contrast)
                    cells.append(_at(load_ratios(sensor.problem((inc,))), end))
                rows.append(cells)
            header = ["contrast, depth", *(f"{o:g} mm" for o in sensor.offsets_mm)]
            out += [*_table(header, rows), ""]
    return out


FLOORS = {PAPER.name: 0.043, LUNG.name: 0.053}
"""The joint fit's 95 % half-width on the homogeneous sample (docs/inclusions.md)."""
LIMIT_RADII_MM = {PAPER.name: (1.5, 2.5, 4.0), LUNG.name: (2.5, 5.0, 7.5)}
LIMIT_CONTRASTS = (2.0, 5.0, 10.0)
_BISECTIONS = 4


def limits(sensors: Sequence[Sensor] = (PAPER, LUNG)) -> list[str]:
    """The deepest centre depth at which an inclusion straight below the tip is still seen
    above the noise floor, by bisection over its depth (quarter models)."""
    out = ["### How deep an inclusion straight below the tip is still seen", ""]
    for sensor in sensors:
        end, floor = sensor.end_depth(), FLOORS[sensor.name]
        out += [f"{sensor.name}; floor {floor:.1%}; deepest visible centre depth (mm):", ""]
        rows = []
        for radius in LIMIT_RADII_MM[sensor.name]:
            one = dataclasses.replace(sensor, inclusion_radius_mm=radius)
            rows.append(
                [f"{2 * radius:g} mm across"]
                + [_deepest(one, contrast, end, floor) for contrast in LIMIT_CONTRASTS]
            )
        out += [*_table(["inclusion", *(f"{c:g}x" for c in LIMIT_CONTRASTS)], rows), ""]
    return out


def _deepest(sensor: Sensor, contrast: float, end: float, floor: float) -> str:
    radius = sensor.inclusion_radius_mm

    def seen(depth: float) -> bool:
        table = load_ratios(sensor.problem((sensor.inclusion(0.0, depth, contrast),)))
        return _at(table, end) - 1.0 > floor

    lo, hi = radius + 0.25, sensor.thickness_mm - radius - 0.25
    if not seen(lo):
        return f"not at {lo:g}"
    if seen(hi):
        return f"> {hi:g} (the base)"
    for _ in range(_BISECTIONS):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if seen(mid) else (lo, mid)
    return f"{lo:.1f}-{hi:.1f}"


def validation() -> list[str]:
    base = PAPER.problem()
    axi = load_table(base.layer())
    raw = load_ratios(base)  # no inclusion: forces == reference
    out = ["### Without inclusions: the 3-D solve against the axisymmetric world", ""]
    pick = list(range(1, 20, 3))
    out += _table(
        ["delta/R", *(f"{axi.depths[k]:.3g}" for k in pick)],
        [["3-D / axisymmetric", *(float(raw.forces[k] / axi.forces[k]) for k in pick)]],
    )
    out += ["", "### On the axis: the world (axisymmetric x 3-D factor) against an"
            " axisymmetric solve holding the inclusion", ""]  # fmt: skip
    rows = []
    for depth, radius, contrast in ((1.2, 0.6, 5.0), (1.5, 1.0, 30.0), (1.2, 0.6, 0.3)):
        inc = Inclusion(0.0, 0.0, depth, radius, contrast)
        factor = load_ratios(dataclasses.replace(base, inclusions=(inc,)))
        held = solve_indentation(base.layer(inclusion=(depth, radius, contrast, 0.45)))
        world = axi.forces * factor.ratios
        rows.append(
            [f"{contrast:g}x, r {radius:g} R at {depth:g} R"]
            + [
                f"{held.forces[k] / axi.forces[k]:.3f} / {world[k] / held.forces[k]:.4f}"
                for k in pick
            ]
        )
    out += _table(
        ["inclusion (effect / world error)", *(f"{axi.depths[k]:.3g}" for k in pick)], rows
    )
    return [*out, "", *_convergence(base, pick)]


def _convergence(base: InclusionProblem, pick: list[int]) -> list[str]:
    inc = Inclusion(0.0, 0.0, 1.2, 0.6, 5.0)
    rows = []
    for fine in (0.2, 0.14, 0.1, 0.07):
        t = load_ratios(dataclasses.replace(base, inclusions=(inc,), fine=fine))
        rows.append([f"{fine:g}", *(float(t.ratios[k]) for k in pick), f"{t.build_seconds:.0f}"])
    far = load_ratios(dataclasses.replace(base, inclusions=(Inclusion(6.0, 0.0, 1.2, 0.6, 5.0),)))
    out = ["### Mesh convergence of the factor (5x, r 0.6 R at 1.2 R, on the axis)", ""]
    out += _table(["fine (R)", *(f"{base.depths()[k]:.3g}" for k in pick), "s"], rows)
    out += ["", f"Far field (the same inclusion 6 R aside): factor {far.ratios.min():.4f}-"
            f"{far.ratios.max():.4f} over the depths."]  # fmt: skip
    return out


def published() -> list[str]:
    """Egorov and Sarvazyan 2008, Table II, under the lung sensor (R = 10 mm)."""
    cases = ((5, 20), (5, 80), (10, 10), (10, 40), (14, 40), (14, 156), (18, 20), (18, 80))
    sensor = dataclasses.replace(LUNG, thickness_mm=35.0, matrix_kpa=5.0)
    end = sensor.end_depth()
    rows = []
    for diameter, modulus in cases:
        inc = Inclusion(0.0, 0.0, 10.0 / 10.0, diameter / 20.0, modulus / 5.0)
        if inc.depth <= inc.radius:
            inc = dataclasses.replace(inc, depth=inc.radius + 0.1)
        t = load_ratios(sensor.problem((inc,)))
        rows.append([f"{diameter} mm, {modulus} kPa", f"{inc.depth * 10:g}", _at(t, end)])
    return [
        f"### Egorov and Sarvazyan's phantoms under the lung sensor (delta/R = {end:.3f})",
        "",
        *_table(["inclusion", "centre depth (mm)", "apparent / matrix"], rows),
    ]


SECTIONS = {
    "validation": validation,
    "visibility": visibility,
    "limits": limits,
    "published": published,
}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.inclusions")
    parser.add_argument("--section", action="append", choices=sorted(SECTIONS))
    args = parser.parse_args(argv)
    for name in args.section or list(SECTIONS):
        print("\n".join(SECTIONS[name]()), "", sep="\n", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
