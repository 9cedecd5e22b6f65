"""The beam's states along a trial's rows, and the strain noise measured on them: what the joint
fit (``estimation.trial.estimate``) and the relaxation fit (``estimation.trial.relaxed``) both read.

The strain noise is measured on the record itself (each row's 3-grating fit has one degree of
freedom left; the median of its squared residual gives sigma), so nothing about the simulator's
noise setting leaks in.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from statistics import NormalDist

import numpy as np
from numpy.typing import NDArray

from ...config.schema import SensorConfig
from ..beam.section import Section, grating_intervals
from ..beam.states import BeamStates, infer_states
from .inputs import EstimatorInputs

Row = tuple[str, float, Sequence[float]]
WAITING = "waiting"  # a gated trial's rows at the stand-off, waiting for a breath hold

FloatArray = NDArray[np.float64]
LOADING_STATES = frozenset({"approach", "contact", "indenting", "buckled"})  # the joint fit's rows
# a row's axial load (N) by the row, (advance, *strains) as recorded: what the estimate's beam
# states hand the recording's tip force (robot.trial.tipforce), so those rows are inferred once
RowLoads = Mapping[tuple[float, ...], float]
_UNIT_SIGMA = 1e-6  # infer_states is linear in sigma: run at 1e-6, rescale by the measured one


def strain_sigma(residual: FloatArray, gratings: int) -> float:
    """Per-grating strain noise from per-row rms residuals of the 2-parameter fit (median-based,
    so a few rows the model misses do not inflate it)."""
    dof = gratings - 2
    ss = gratings * residual**2  # sum of squares per row ~ sigma^2 chi2(dof)
    # chi2(1)'s median is exact through the normal; Wilson-Hilferty (< 1 % off) above
    median = NormalDist().inv_cdf(0.75) ** 2 if dof == 1 else dof * (1 - 2 / (9 * dof)) ** 3
    return max(math.sqrt(float(np.median(ss)) / median), 1e-9)


def record_states(
    advance: FloatArray,
    strains: FloatArray,
    inputs: EstimatorInputs,
    sensor: SensorConfig,
    section: Section,
) -> tuple[BeamStates, float]:
    """The beam's states along rows (advance (N,), strains (N, G)) at unit strain noise, and
    the strain noise measured on them (the joint fit's and the relaxation fit's)."""
    return states_at(strains, record_lengths(advance, inputs), sensor, section)


def states_at(
    strains: FloatArray, lengths: FloatArray, sensor: SensorConfig, section: Section
) -> tuple[BeamStates, float]:
    """The beam's states along the record at unit strain noise, and the strain noise measured
    on the record (the states' sigmas scale with it)."""
    intervals = grating_intervals(sensor, 0.0)[None, :, :] + lengths[:, None, None]
    states = infer_states(
        strains, intervals, lengths, section.EA, section.fiber_offset, _UNIT_SIGMA
    )
    return states, strain_sigma(states.residual, strains.shape[1]) / _UNIT_SIGMA


def on_beam(lengths: FloatArray, sensor: SensorConfig) -> NDArray[np.bool_]:
    """Per row, whether every used grating lies on the exposed beam at that exposed length (m):
    the rows the beam model can read. Before the sensor has left the tube (a robot trial's
    positioning, the stage behind the tube's flush translation) a row has no beam state."""
    inner = grating_intervals(sensor, 0.0)[:, 0].min()  # the innermost grating's start at L = 0
    return np.asarray((lengths > 0) & (lengths + inner >= 0))


def record_lengths(advance: FloatArray, inputs: EstimatorInputs) -> FloatArray:
    """The exposed length (m) at each row: the bench's fixed one, or the robot's advance past
    the tube's flush translation (<= 0 while the sensor is still inside the tube)."""
    return inputs.stage.exposed_lengths(advance)


def row_loads(
    advance: FloatArray, strains: FloatArray, states: BeamStates
) -> dict[tuple[float, ...], float]:
    """Each row's axial load keyed by the row (:data:`RowLoads`)."""
    keys = np.column_stack([advance, strains]).tolist()
    return {tuple(k): p for k, p in zip(keys, states.P.tolist(), strict=True)}


def last_attempt(
    rows: list[Row], times: Sequence[float] | None, loads: Sequence[float | None] | None
) -> tuple[list[Row], Sequence[float] | None, Sequence[float | None] | None]:
    """The rows (and their times and tip loads) of a gated trial's last attempt: past the last
    wait for a breath hold that follows a retraction (``robot.body``); all of a trial of one.

    >>> states = ["waiting", "approach", "retracting", "waiting", "approach"]
    >>> last_attempt([(s, 0.0, ()) for s in states], None, None)[0]
    [('approach', 0.0, ())]
    """
    start, retracted = 0, False
    for i, (state, _, _) in enumerate(rows):
        retracted = retracted or state == "retracting"
        if retracted and state == WAITING:
            start = i + 1
    if not start:
        return rows, times, loads
    later = None if times is None else times[start:]
    return rows[start:], later, None if loads is None else loads[start:]
