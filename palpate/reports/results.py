"""A campaign's results on disk, in its run folder beside the logs, written as trials finish.

- ``trials.csv``: one row per trial (:data:`TRIAL_COLUMNS`): the joint fit with its 95 %
  interval, the paper's single-point estimate (Eqs. 13-14) beside it, the verdict and its
  reasons, how the trial ended, and in simulation the truth. A row is appended as each trial
  finishes; at the end (and on ``--resume``, from the trials read back) the file is written
  whole, in the campaign's order.
- ``samples.csv``: one row per sample, as the paper's Tables I and II (:data:`SAMPLE_COLUMNS`).
- ``results.json``: what ``--json`` prints.

Spreadsheet-ready: moduli in kPa, lengths in mm, angles in degrees, empty cells for no value.

    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> results = CampaignResults(folder)
    >>> results.add({"trial": "S1-a", "sample": "S1", "joint_kpa": 101.2, "verdict": "ok"})
    >>> (folder / "trials.csv").read_text().splitlines()[1].split(",")[:3]
    ['S1-a', 'S1', '']
"""

from __future__ import annotations

import csv
import json
import os
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from palpate.campaigns.pooled import POOLED_COLUMNS

TRIALS_CSV, SAMPLES_CSV, RESULTS_JSON = "trials.csv", "samples.csv", "results.json"

# (column, the trial row's key or a function of the row)
TRIAL_COLUMNS: tuple[tuple[str, Any], ...] = (
    ("trial", "trial"),
    ("sample", "sample"),
    ("tube", "tube"),
    ("orientation", "orientation"),
    ("roll_deg", "roll_deg"),
    ("exposed_length_mm", "exposed_length_mm"),
    ("joint_kpa", "joint_kpa"),
    ("joint_ci_low_kpa", lambda r: (r.get("joint_ci_kpa") or [None, None])[0]),
    ("joint_ci_high_kpa", lambda r: (r.get("joint_ci_kpa") or [None, None])[1]),
    ("paper_kpa", "paper_kpa"),
    ("verdict", "verdict"),
    ("reasons", lambda r: "; ".join(r.get("verdict_reasons") or [])),
    ("state", "state"),
    ("reason", "reason"),
    ("true_kpa", "true_kpa"),
    ("reference_kpa", "reference_kpa"),
)
SAMPLE_COLUMNS = (
    "sample",
    "trials",
    "ok",
    "suspect",
    "none",
    "joint_mean_kpa",
    "true_kpa",
    "joint_rmse_kpa",
    "joint_iqr_kpa",
    "joint_relative_error",
    "intervals_holding_truth",
    "trials_with_number",
    "paper_mean_kpa",
    "paper_relative_error",
    *POOLED_COLUMNS,
)


def trial_cells(row: Mapping[str, Any]) -> list[object]:
    """One trial row (``--json``'s) as ``trials.csv``'s cells."""
    cells = []
    for _, key in TRIAL_COLUMNS:
        value = key(row) if callable(key) else row.get(key)
        cells.append("" if value is None else value)
    return cells


class CampaignResults:
    """A run folder's results files (see the module docstring)."""

    def __init__(self, run_dir: Path) -> None:
        self.run_dir = run_dir

    def start(self, rows: Iterable[Mapping[str, Any]]) -> None:
        """``trials.csv`` anew with ``rows`` (a resumed run's trials read back; none at first)."""
        self.run_dir.mkdir(parents=True, exist_ok=True)
        _write_csv(self.run_dir / TRIALS_CSV, [c for c, _ in TRIAL_COLUMNS], map(trial_cells, rows))

    def add(self, row: Mapping[str, Any]) -> None:
        """Append one finished trial's row to ``trials.csv`` (its header first if new)."""
        path = self.run_dir / TRIALS_CSV
        self.run_dir.mkdir(parents=True, exist_ok=True)
        new = not path.exists() or path.stat().st_size == 0
        with open(path, "a", encoding="utf-8", newline="") as fh:
            writer = csv.writer(fh)
            if new:
                writer.writerow([c for c, _ in TRIAL_COLUMNS])
            writer.writerow(trial_cells(row))

    def finish(
        self,
        rows: Sequence[Mapping[str, Any]],
        samples: Sequence[Mapping[str, Any]],
        payload: Mapping[str, Any],
    ) -> list[Path]:
        """Every results file whole: the trials in the campaign's order, the samples and the
        ``--json`` payload. Returns the files written."""
        self.start(rows)
        _write_csv(
            self.run_dir / SAMPLES_CSV,
            list(SAMPLE_COLUMNS),
            ([_blank(s.get(c)) for c in SAMPLE_COLUMNS] for s in samples),
        )
        _replace(self.run_dir / RESULTS_JSON, json.dumps(payload, indent=2) + "\n")
        return [self.run_dir / name for name in (RESULTS_JSON, TRIALS_CSV, SAMPLES_CSV)]


def _blank(value: object) -> object:
    return "" if value is None else value


def _write_csv(path: Path, header: list[str], rows: Iterable[Sequence[object]]) -> None:
    tmp = path.with_name(f".{path.name}.tmp")
    with open(tmp, "w", encoding="utf-8", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(header)
        writer.writerows(rows)
    os.replace(tmp, path)


def _replace(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` whole or not at all (a kill mid-write leaves the old file)."""
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, path)
