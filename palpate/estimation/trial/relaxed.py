"""The relaxation estimate of a trial with a hold (``estimation.relaxation``), on the trial's
record or a log's samples: the same function on ``palpate sim``, ``trial`` and ``replay``.

The rows from the approach to the end of the hold (state, advance, strains, with each row's
time) give the beam's load and end shortening (``estimation.beam.states``, the strain noise
measured on these rows as for the joint fit); with a tip force grating the load is the
grating's, as the joint fit reads it (its noise measured on the same rows,
``estimation.detect.contact.difference_sigma``): a light sensor's strains carry its load at a
few noise widths, the grating at hundreds. The joint fit (which reads the loading rows only,
so its number is what it is without a hold) gives the contact, the load offset and its
model-form bound; the relaxation is fitted under every hypothesis of the belief
(``estimation.relaxation.beliefs``), not at the elastic fit's best, which a relaxing record
misleads. A record without a hold
has no relaxation estimate (None): old logs replay as they were.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ...config.schema import SensorConfig
from ..beam.section import Section
from ..detect.contact import difference_sigma
from ..jointfit import JointFit
from ..relaxation import RelaxationFit, RelaxationRecord, fit_over_beliefs
from .inputs import EstimatorInputs
from .lean import row_in, rows_in
from .states import LOADING_STATES, record_states

HOLD_STATE = "holding"
RECORD_STATES = LOADING_STATES | {HOLD_STATE}
SLOW_STATES = frozenset({"buckled", HOLD_STATE})  # the load barely moves: rows averaged
BLOCK = 10  # rows a block of the slow states averages
Row = tuple[str, float, Sequence[float]]
FloatArray = NDArray[np.float64]


def has_hold(rows: Sequence[Row]) -> bool:
    return any(r[0] == HOLD_STATE for r in rows)


def relaxation_of(
    rows: Sequence[Row],
    times: Sequence[float],
    inputs: EstimatorInputs,
    sensor: SensorConfig,
    section: Section,
    joint: JointFit | None,
    tip_forces: Sequence[float | None] | None = None,
) -> RelaxationFit | None:
    """The relaxation fit of a record with a hold (None without one); ``times`` (s) one per row,
    ``tip_forces`` (N) one per row from a tip grating (None: the load from the strains)."""
    if not has_hold(rows) or inputs.rigid:
        return None
    if len(times) != len(rows):
        raise ValueError(f"{len(times)} times for {len(rows)} rows: one time per row")
    if joint is None or not joint.success or joint.modulus is None or joint.best is None:
        return RelaxationFit(False, "no joint fit to start from")
    gratings = len(sensor.used_gratings)
    tips = _tips(rows, tip_forces, gratings)
    blocks = _blocks(rows, gratings)
    t = _means(blocks, lambda i: times[i])
    advance = _means(blocks, lambda i: rows[i][1])
    strains = _means(blocks, lambda i: rows[i][2]).reshape(-1, gratings)
    hold_t = [times[i] for i, r in enumerate(rows) if r[0] == HOLD_STATE]
    _, k = record_states(*rows_in(rows, RECORD_STATES, gratings), inputs, sensor, section)
    states, _ = record_states(advance, strains, inputs, sensor, section)
    thin = 1.0 / np.sqrt([len(b) for b in blocks])  # a block's mean has 1/sqrt(n) of a row's
    load, sigma_load = states.P, k * thin * states.sigma_P
    if tips is not None:
        load = _means(blocks, lambda i: tips[i])
        sigma_load = difference_sigma(tips[np.isfinite(tips)]) * thin
    record = RelaxationRecord(
        times=t,
        load=np.asarray(load - (joint.load_offset or 0.0)),
        depth_base=np.asarray(advance - states.e),
        sigma_load=np.asarray(sigma_load),
        sigma_depth=np.sqrt((k * thin * states.sigma_e) ** 2 + inputs.encoder_resolution**2 / 12),
        hold=_held(hold_t),
    )
    return fit_over_beliefs(
        record,
        inputs.belief(),
        contact_bracket(joint),
        joint.modulus,
        model_form=joint.model_form or 0.0,
        confidence=joint.confidence,
    )


def contact_bracket(joint: JointFit) -> tuple[float, float, float]:
    """(low, x0, high) of the joint fit's contact (m), in order. Its interval is on the fit's
    grid of positions and x0 is refined between them: x0 may lie past the interval's grid end
    by less than a step (a relaxing lung trial's did, by 0.8 um); the bracket holds it."""
    x0 = float(joint.contact or 0.0)
    low, high = joint.contact_low or x0, joint.contact_high or x0
    return min(low, x0), x0, max(high, x0)


def _held(times: Sequence[float]) -> float:
    """The hold's length (s): its rows' span and one tick (each row stands for a tick)."""
    if len(times) < 2:
        return 0.0
    return float(times[-1] - times[0] + np.median(np.diff(times)))


def _tips(
    rows: Sequence[Row], tip_forces: Sequence[float | None] | None, gratings: int
) -> FloatArray | None:
    """The tip grating's load (N) of every row (NaN where a row has none), None without a
    grating or where a row of the record has no finite load."""
    if not tip_forces or len(tip_forces) != len(rows):
        return None
    tips = np.array([math.nan if f is None else float(f) for f in tip_forces])
    picked = [row_in(*r, RECORD_STATES, gratings) for r in rows]
    return tips if np.all(np.isfinite(tips[picked])) else None


def _blocks(rows: Sequence[Row], gratings: int) -> list[list[int]]:
    """The record's rows (indices) in blocks: the loading rows one by one, the buckled and held
    rows ``BLOCK`` at a time. Past buckling the load is nearly constant and the creep slow,
    while the end shortening read from the strains is noisy; a depth that noisy, regressed on,
    pulls the fit (errors in variables: the noise of e is also squared into e = z^2 L).
    Averaging the strains before the beam states are inferred takes both down by the block's
    size."""
    blocks: list[list[int]] = []
    block: list[int] = []

    def flush() -> None:
        if block:
            blocks.append(block.copy())
            block.clear()

    for i, (state, advance, row_strains) in enumerate(rows):
        if not row_in(state, advance, row_strains, RECORD_STATES, gratings):
            continue
        if state not in SLOW_STATES:
            flush()
            block.append(i)
            flush()
            continue
        if block and rows[block[0]][0] != state:
            flush()
        block.append(i)
        if len(block) == BLOCK:
            flush()
    flush()
    return blocks


def _means(blocks: list[list[int]], value: Callable[[int], Any]) -> FloatArray:
    """Each block's mean of ``value`` (a row's number or vector, by the row's index)."""
    return np.asarray([np.mean(np.asarray([value(i) for i in b]), axis=0) for b in blocks])
