"""The tip force a trial's recording derives at its close (``/tip/wrench``): the tip grating's
load where the sensor has one, else the axial load of the estimator's beam states. Handed to
``robot.records`` (the log writer and the export) as a function: the records serialise, this
module computes."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ...estimation.trial.inputs import header_sensor
from ...estimation.trial.states import RowLoads, on_beam, record_lengths, states_at
from ..records.recording import McapRecorder


def axial_loads(recorder: McapRecorder, known: RowLoads | None = None) -> list[float] | None:
    """The axial load (N) at every sample of ``recorder``: the tip grating's where the sensor
    has one, else from its strains (the estimator's beam states), NaN where a sample has no
    beam state (strains incomplete, or the sensor not yet out of the tube: such rows are never
    handed to the beam model); None when the header lacks the sensor, the section or the
    estimator's inputs. ``known``: loads the trial's estimate already inferred, by row
    (``estimation.trial.states.row_loads``); only the other rows are inferred here (each row's
    state is its own least-squares fit: a row inferred in another batch differs in the last
    bits of its Gauss-Newton stop, below 1e-12 relative)."""
    tips = [x.tip_force for x in recorder.samples]
    if any(math.isfinite(f) for f in tips):
        return tips
    try:
        sensor, section, inputs = header_sensor(recorder.header)
    except (KeyError, TypeError, ValueError):  # ConfigError is a ValueError
        return None
    gratings = len(sensor.used_gratings)
    samples = recorder.samples
    whole = [i for i, x in enumerate(samples) if _whole([x.advance, *x.strains], gratings + 1)]
    loads = [math.nan] * len(samples)
    if not whole:
        return loads
    advance = np.asarray([samples[i].advance for i in whole], dtype=np.float64)
    lengths = record_lengths(advance, inputs)
    keep = on_beam(lengths, sensor)
    lengths = lengths[keep]
    rows = [i for i, k in zip(whole, keep.tolist(), strict=True) if k]
    known = known or {}
    todo = []
    for j, i in enumerate(rows):
        found = known.get((samples[i].advance, *samples[i].strains))
        if found is None:
            todo.append(j)
        else:
            loads[i] = found
    if not todo:
        return loads
    strains = np.asarray([samples[rows[j]].strains for j in todo], dtype=np.float64)
    states, _ = states_at(strains, lengths[todo], sensor, section)
    for j, load in zip(todo, states.P.tolist(), strict=True):
        loads[rows[j]] = load
    return loads


def _whole(strains: list[Any], gratings: int) -> bool:
    return len(strains) == gratings and all(
        isinstance(v, int | float) and math.isfinite(v) for v in strains
    )
