"""Regenerate the force tables shipped with the package: ``python -m sim.fem.generate``.

The shipped problems are the scenes' samples: the paper's phantoms (tip R = 3.5 mm, 10 mm layers
in a 40 mm radius dish, nu = 0.45, bonded, frictionless and full stick; linear and neo-Hookean), the
soft-tissue designs (R = 6 mm, 20 mm layers), the half-space stand-in (a block 200 R deep and
wide, nu = 0.45, for any tip: ``sim.sample_law``) and the layers of ``config/scenes/layers/``.
tests/sim/test_sample_law.py checks that every
sample of the shipped scenes finds its table here. Each table is solved afresh, written to
``sim/fem/tables/<key>.npz``, and its key, build time and status printed; tables that no shipped
problem names any more are removed. Options: ``--only NAME`` (repeatable), ``--list``.
"""

from __future__ import annotations

import argparse
import sys

from .problem import LayerProblem
from .table import SHIPPED_DIR, save_table, solve_table, table_key

_PAPER = {"tip_radius": 3.5e-3, "thickness": 10e-3, "radius": 40e-3, "poisson": 0.45}
_SOFT = {"tip_radius": 6e-3, "thickness": 20e-3, "radius": 40e-3, "poisson": 0.45}

SHIPPED: dict[str, LayerProblem] = {
    "paper-linear": LayerProblem.from_dimensions(**_PAPER),
    "paper-neo-hookean": LayerProblem.from_dimensions(**_PAPER, material="neo-hookean"),
    # a sample's default friction (0.5) sticks on these layers (sim.sample_law.contact_condition)
    "paper-linear-stick": LayerProblem.from_dimensions(**_PAPER, contact="stick"),
    "paper-neo-hookean-stick": LayerProblem.from_dimensions(
        **_PAPER, material="neo-hookean", contact="stick"
    ),
    "soft-linear": LayerProblem.from_dimensions(**_SOFT),
    "soft-neo-hookean": LayerProblem.from_dimensions(**_SOFT, material="neo-hookean"),
    "half-space-linear": LayerProblem(thickness_ratio=200.0, radius_ratio=200.0, poisson=0.45),
    "half-space-linear-stick": LayerProblem(
        thickness_ratio=200.0, radius_ratio=200.0, poisson=0.45, contact="stick"
    ),
}
for _h in (1.5e-3, 3e-3, 5e-3):
    for _nu, _base in ((0.45, "bonded"), (0.45, "sliding"), (0.49, "bonded"), (0.49, "sliding")):
        SHIPPED[f"layers-{_h * 1e3:g}mm-{_base}-nu{_nu:g}"] = LayerProblem.from_dimensions(
            3.5e-3, _h, 40e-3, poisson=_nu, base=_base, contact="frictionless"
        )
for _h in (20e-3, 30e-3):
    SHIPPED[f"layers-deep-{_h * 1e3:g}mm"] = LayerProblem.from_dimensions(
        3.5e-3, _h, 40e-3, poisson=0.45, contact="frictionless"
    )
for _h in (10e-3, 20e-3, 40e-3):
    for _nu in (0.45, 0.49):
        SHIPPED[f"lung-{_h * 1e3:g}mm-nu{_nu:g}"] = LayerProblem.from_dimensions(
            10e-3, _h, 60e-3, poisson=_nu, material="neo-hookean", contact="stick"
        )
# thin neo-Hookean layers under the paper's tip, frictionless and sticking
# (``config/scenes/layers/neo-hookean.yaml``, issue 41's finite strain), solved to delta/h = 0.5
# (``problem.THIN_STRAIN_MAX``; the scene reaches 0.38)
_NH = {"poisson": 0.45, "material": "neo-hookean"}
for _h in (1.5e-3, 2e-3, 3e-3):
    for _base in ("bonded", "sliding"):
        for _contact in ("frictionless", "stick"):
            SHIPPED[f"layers-nh-{_h * 1e3:g}mm-{_base}-{_contact}"] = LayerProblem.from_dimensions(
                3.5e-3, _h, 40e-3, **_NH, base=_base, contact=_contact
            )
# the mismatch scenes (``config/scenes/mismatch/``): the paper's layer at other nu, sliding,
# and at other thicknesses
for _nu in (0.40, 0.42, 0.47, 0.49):
    SHIPPED[f"mismatch-nu{_nu:g}"] = LayerProblem.from_dimensions(
        **{**_PAPER, "poisson": _nu}, contact="stick"
    )
SHIPPED["mismatch-sliding"] = LayerProblem.from_dimensions(
    **_PAPER, base="sliding", contact="stick"
)
for _h in (5e-3, 6e-3, 8e-3, 12e-3, 16e-3, 20e-3, 30e-3):
    SHIPPED[f"mismatch-{_h * 1e3:g}mm"] = LayerProblem.from_dimensions(
        **{**_PAPER, "thickness": _h}, contact="stick"
    )
# wet tissue's friction (0.05) slides: ``config/scenes/lung/slip.yaml``
SHIPPED["lung-20mm-nu0.45-frictionless"] = LayerProblem.from_dimensions(
    10e-3, 20e-3, 60e-3, poisson=0.45, material="neo-hookean", contact="frictionless"
)
# the channel-sized lung sensors' tips (``config/scenes/invivo/lumen-*.yaml``: R = 1.3, 0.9 mm)
for _r in (1.3e-3, 0.9e-3):
    for _h in (10e-3, 20e-3, 40e-3):
        for _nu in (0.45, 0.49):
            SHIPPED[f"lumen-R{_r * 1e3:g}-{_h * 1e3:g}mm-nu{_nu:g}"] = LayerProblem.from_dimensions(
                _r, _h, 60e-3, poisson=_nu, material="neo-hookean", contact="stick"
            )
"""The problems whose tables ship in ``sim/fem/tables``, by name: the paper's and the soft
designs' phantoms, the half-space stand-in, the thin and deep layers of
``config/scenes/layers/`` (R = 3.5 mm, frictionless tip; the neo-Hookean ones with a sticking tip
too), the mismatch scenes' layers (other nu,
sliding, 5-30 mm) and the lung scene's neo-Hookean layers
(R = 10 mm, the 1-20 kPa design's tip; ``config/scenes/lung/``, its slip scene frictionless),
and the same layers under the channel-sized sensors' tips (``config/scenes/invivo/lumen-*``)."""


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m sim.fem.generate", description=__doc__)
    parser.add_argument("--only", action="append", choices=sorted(SHIPPED), default=None)
    parser.add_argument("--list", action="store_true", help="print names and keys, solve nothing")
    args = parser.parse_args(argv)
    names = args.only or sorted(SHIPPED)
    if args.list:
        for name in names:
            print(f"{name:20s} {table_key(SHIPPED[name])}  {SHIPPED[name]}")
        return 0
    status = 0
    for name in names:
        table = solve_table(SHIPPED[name])
        path = save_table(table, SHIPPED_DIR)
        print(f"{name:20s} {path.name}  {table.build_seconds:6.1f} s  {table.message}", flush=True)
        status |= 0 if table.success else 1
    if args.only is None:
        wanted = {f"{table_key(p)}.npz" for p in SHIPPED.values()}
        for stale in SHIPPED_DIR.glob("*.npz"):
            if stale.name not in wanted:
                stale.unlink()
                print(f"removed {stale.name}")
    return status


if __name__ == "__main__":
    sys.exit(main())
