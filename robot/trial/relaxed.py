"""The relaxation estimate of a trial with a hold (``estimation.relaxation``), on the trial's
record or a log's samples: the same function on ``palpate sim``, ``trial`` and ``replay``.

The rows from the approach to the end of the hold (state, advance, strains, with each row's
time) give the beam's load and end shortening (``estimation.beamstate``, the strain noise
measured on these rows as for the joint fit); the joint fit (which reads the loading rows only,
so its number is what it is without a hold) gives the contact, the load offset, the best
hypothesis's contact law and compliance, and its model-form bound. A record without a hold
has no relaxation estimate (None): old logs replay as they were.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ...config.schema import SensorConfig
from ...estimation.belief import Hypothesis
from ...estimation.jointfit import JointFit
from ...estimation.relaxation import RelaxationFit, RelaxationRecord, fit_relaxation
from ...estimation.section import Section
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
) -> RelaxationFit | None:
    """The relaxation fit of a record with a hold (None without one); ``times`` (s) one per row."""
    if not has_hold(rows) or inputs.rigid:
        return None
    if len(times) != len(rows):
        raise ValueError(f"{len(times)} times for {len(rows)} rows: one time per row")
    if joint is None or not joint.success or joint.modulus is None or joint.best is None:
        return RelaxationFit(False, "no joint fit to start from")
    t, advance, strains, counts = _blocks(rows, times, len(sensor.used_gratings))
    hold_t = [times[i] for i, r in enumerate(rows) if r[0] == HOLD_STATE]
    _, k = record_states(
        *rows_in(rows, RECORD_STATES, len(sensor.used_gratings)), inputs, sensor, section
    )
    states, _ = record_states(advance, strains, inputs, sensor, section)
    thin = 1.0 / np.sqrt(counts)  # a block's mean has 1/sqrt(n) of a row's noise
    best = Hypothesis.described(joint.best, inputs.contact_radius, inputs.belief().layer_law)
    law, compliance = best.law, best.compliance
    record = RelaxationRecord(
        times=t,
        load=np.asarray(states.P - (joint.load_offset or 0.0)),
        depth_base=np.asarray(advance - states.e - compliance * states.P),
        sigma_load=np.asarray(k * thin * states.sigma_P),
        sigma_depth=np.sqrt((k * thin * states.sigma_e) ** 2 + inputs.encoder_resolution**2 / 12),
        hold=_held(hold_t),
    )
    x0 = float(joint.contact or 0.0)
    contact = (joint.contact_low or x0, x0, joint.contact_high or x0)
    return fit_relaxation(
        record,
        law,
        contact,
        joint.modulus,
        model_form=joint.model_form or 0.0,
        confidence=joint.confidence,
    )


def _held(times: Sequence[float]) -> float:
    """The hold's length (s): its rows' span and one tick (each row stands for a tick)."""
    if len(times) < 2:
        return 0.0
    return float(times[-1] - times[0] + np.median(np.diff(times)))


def _blocks(
    rows: Sequence[Row], times: Sequence[float], gratings: int
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """(times, advance, strains, rows per block) of the record: the loading rows one by one,
    the buckled and held rows averaged ``BLOCK`` at a time. Past buckling the load is nearly
    constant and the creep slow, while the end shortening read from the strains is noisy; a
    depth that noisy, regressed on, pulls the fit (errors in variables: the noise of e is also
    squared into e = z^2 L). Averaging the strains before the beam states are inferred takes
    both down by the block's size."""
    out_t: list[float] = []
    out_u: list[float] = []
    out_s: list[FloatArray] = []
    counts: list[int] = []
    block: list[int] = []

    def flush() -> None:
        if block:
            out_t.append(float(np.mean([times[i] for i in block])))
            out_u.append(float(np.mean([rows[i][1] for i in block])))
            out_s.append(np.mean(np.asarray([rows[i][2] for i in block]), axis=0))
            counts.append(len(block))
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
    averaged = np.asarray(out_s, dtype=np.float64).reshape(-1, gratings)
    return np.asarray(out_t), np.asarray(out_u), averaged, np.asarray(counts, dtype=np.float64)
