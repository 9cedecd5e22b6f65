"""A simulated campaign's results as one object: what ``palpate sim --json`` prints, what its
run folder's ``results.json`` holds and what :func:`palpate.simulate` returns."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from palpate.calibration import calibrate
from palpate.campaigns.campaign import median_abs_relative_error, summarize_campaign
from palpate.config.scene import SceneConfig
from palpate.config.schema import StackConfig
from palpate.reports import verdicts
from palpate.reports.campaign_table import kpa_fields, sample_records
from palpate.simulation.trial import TrialOutcome
from palpate.simulation.world import tissue_description

METHOD = (
    "joint fit (contact-point-free; joint_kpa, ok trials in the medians); the paper's "
    "single-point estimate (Eqs. 13-14) per trial as paper_kpa"
)


@dataclass
class CampaignReport:
    """One campaign's results: its trials (typed outcomes), the per-sample table, the rig's
    calibration found on rigid references, and :meth:`as_dict`, the ``--json`` payload.

    Attributes:
        scene: the scene's name; trials: each trial's outcome (``.as_dict()``: its JSON row,
            ``.modulus("joint")``, ``.joint``, ``.verdict``, ...); samples: one record per
            sample (``samples.csv``'s columns); calibration: compliance (m/N) interval per rig.
    """

    scene: str
    trials: list[TrialOutcome]
    samples: list[dict[str, Any]]
    calibration: dict[str, tuple[float, float]]
    payload: dict[str, Any] = field(repr=False)

    def as_dict(self) -> dict[str, Any]:
        """What ``palpate sim --json`` prints for this campaign."""
        return self.payload


def campaign_report(
    scene: SceneConfig,
    stack: StackConfig,
    outcomes: list[TrialOutcome],
    *,
    run: dict[str, Any],
    wall: float,
    figures: list[str] | None = None,
) -> CampaignReport:
    """The report of ``outcomes``; ``run``: where and how it ran (``run_dir``, ``log_dir``,
    ``transport``, ``seed``: the payload's first keys), ``wall``: its wall time (s)."""
    outlier_above = scene.campaign.outlier_above
    rows = summarize_campaign(outcomes, outlier_above)
    records = sample_records(outcomes, rows, outlier_above)
    sim_time = sum(o.sim_time for o in outcomes)
    payload: dict[str, Any] = {
        "scene": scene.name,
        **run,
        "trials": [o.as_dict() for o in outcomes],
        "samples": [
            {**rec, "joint_median_kpa": kpa_fields(r.summary.__dict__).get("median_kpa")}
            | {"tissue_model": tissue_description(scene, stack, r.sample)}
            for r, rec in zip(rows, records, strict=True)
        ],
        "median_abs_relative_error": median_abs_relative_error(outcomes),
        "method": METHOD,
        "median_abs_relative_error_paper": median_abs_relative_error(outcomes, "paper"),
        "wall_s": wall,
        "simulated_s": sim_time,
        "speedup": sim_time / wall if wall > 0 else None,
        "figures": figures or [],
    }
    payload.update(verdicts.verdict_payload(outcomes, scene.campaign.classify_at))
    found = calibrate(
        (o.spec.stage.rig_key, o.calibration) for o in outcomes if o.calibration is not None
    )
    if found:
        payload["calibration"] = {k: [lo * 1e3, hi * 1e3] for k, (lo, hi) in found.items()}
    return CampaignReport(scene.name, list(outcomes), records, found, payload)
