"""Design a sensor for a tissue modulus range, then try it on simulated phantoms across the range.

``palpate design --modulus-range 1:10 --unit kPa`` proposes the fiber, wires, tip radius and
exposed length (``design``), prints the predicted indentation at buckling at both
ends of the range with every check's margin, then runs a short simulated bench campaign with
the proposed sensor on phantoms spread over the range (``--no-sim`` skips it). The first line
says whether the proposal is usable (``palpate.campaigns.designcheck.design_verdict``: every
phantom estimated within ``--tolerance-pct``, no trial failing, the tip's sag within its limit)
and why not; ``--json`` has ``usable`` and ``reasons``. Exit 0 for a usable (or unchecked)
design, 1 for one that is not usable, 2 when no design satisfies the constraints (the message
names the failing constraint).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from palpate.commands.design_inputs import register
from palpate.reports.design import print_report
from palpate.sensor_design.tipgrating import TipGratingChoice
from palpate.sensor_design.weight import WeightCheck
from palpate.services.design import DesignRequest, evaluate, sag_text

EXIT_NO_DESIGN = 2
__all__ = ["register", "run"]  # register: the arguments


def _print_tip(
    tip: TipGratingChoice | None, weight: WeightCheck | None, written: Path | None
) -> None:
    if tip is not None:
        print(
            f"\ntip grating: {tip.sensitivity_pm_per_mn:g} pm/mN, range {tip.range_mn:.3g} mN, "
            f"element {tip.compliance_mm_per_n:.3g} mm/N, resolution {tip.resolution_mn:.3g} mN "
            f"({tip.resolution_share:.2%} of P_cr at 1 sigma)"
        )
    if weight is not None:
        advice = ""
        if not weight.ok:
            advice = (
                ": use it pointing vertically or with the fiber bending in a horizontal plane "
                "(docs/lung.md)"
            )
            if tip is not None:  # a tilted beam's sag fools a strain threshold, not the load
                advice += (
                    "; tilted, read its buckling from the tip load's plateau "
                    "(campaign.detector: tip, docs/invivo.md)"
                )
        print(f"weight: held across, {sag_text(weight)}{advice}")
    if written is not None:
        print(f"wrote {written}")


def run(args: argparse.Namespace) -> int:
    found = evaluate(DesignRequest.from_options(args))
    if args.json:
        print(json.dumps(found.as_dict(), indent=2))
    else:
        print(found.headline())
        if found.lumen is not None:
            print(found.lumen.text())
        print_report(found.result, found.constraints, found.check)
        _print_tip(found.tip, found.weight, args.write)
    if not found.result.success:
        return EXIT_NO_DESIGN
    return 0 if found.verdict.usable is not False else 1
