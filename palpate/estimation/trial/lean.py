"""The load's lean measured on a trial's record (``estimation.pose.misalignment``), trial and
replay.

The rows before buckling (states approach, contact, indenting) with their exposed lengths go to
:func:`estimation.pose.misalignment.measure_lean`; the rows after (``buckled``) are the elastica's,
which the lateral load's linear shape does not describe. Where the lean shows the tip slid,
every loading row (the slide goes on past the detector's mark: nothing buckled) goes with its
advance to :func:`estimation.pose.slip_path.measure_slip_path`, the misalignment from the tip's
path.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable, Sequence

import numpy as np
from numpy.typing import NDArray

from ...config.schema import SensorConfig
from ..beam.section import Section, grating_intervals
from ..pose.misalignment import Lean, measure_lean
from ..pose.slip_path import measure_slip_path
from .inputs import EstimatorInputs
from .states import LOADING_STATES, record_lengths

PRE_BUCKLING = frozenset({"approach", "contact", "indenting"})


def row_in(
    state: str, advance: float, strains: Sequence[float], states: frozenset[str], gratings: int
) -> bool:
    """Whether a (state, advance, strains) row is one :func:`rows_in` picks: in ``states``,
    every grating read, and the stage measured (a tick whose servo read was missed has no
    advance: NaN)."""
    return state in states and len(strains) == gratings and math.isfinite(advance)


def rows_in(
    rows: Iterable[tuple[str, float, Sequence[float]]], states: frozenset[str], gratings: int
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(advance (N,), strains (N, G)) of the (state, advance, strains) rows in ``states`` with
    all ``gratings``, in order."""
    adv: list[float] = []
    eps: list[Sequence[float]] = []
    for state, advance, strains in rows:
        if row_in(state, advance, strains, states, gratings):
            adv.append(advance)
            eps.append(strains)
    x = np.asarray(adv, dtype=np.float64)
    return x, np.asarray(eps, dtype=np.float64).reshape(-1, gratings)


def grating_spans_from_tip(sensor: SensorConfig) -> NDArray[np.float64]:
    """(G, 2): each used grating's (d0, d1), metres from the sensor tip (the arcs of
    ``sensor.strain.grating_intervals`` at L = 0, s = -d, turned round)."""
    arcs = grating_intervals(sensor, 0.0)
    return np.stack([-arcs[:, 1], -arcs[:, 0]], axis=1)


def lean_of_rows(
    rows: Iterable[tuple[str, float, Sequence[float]]],
    sensor: SensorConfig,
    section: Section,
    inputs: EstimatorInputs,
) -> Lean:
    """The lean from (state, advance, strains) rows, at the exposed lengths ``inputs`` give
    (``estimation.trial.states.record_lengths``); where the tip slid, the misalignment from its path
    beside it."""
    rows = list(rows)  # read twice: the rows before buckling, then all the loading rows
    gratings = len(sensor.used_gratings)
    x, strains = rows_in(rows, PRE_BUCKLING, gratings)
    if not x.size:
        return Lean(False, "no rows before buckling")
    from_tip = grating_spans_from_tip(sensor)
    lean = measure_lean(
        strains, record_lengths(x, inputs), from_tip, section.EA, section.EI, section.fiber_offset
    )
    if not lean.lateral:
        return lean
    x, strains = rows_in(rows, LOADING_STATES, gratings)  # the slide goes on past the detector
    path = measure_slip_path(
        strains,
        x,
        record_lengths(x, inputs),
        from_tip,
        section.EA,
        section.EI,
        section.fiber_offset,
    )
    if not path.success:
        return dataclasses.replace(lean, message=f"no misalignment from the path: {path.message}")
    return dataclasses.replace(lean, misalignment=path.angle, misalignment_sigma=path.sigma)


def loading_tip(
    rows: list[tuple[str, float, Sequence[float]]],
    tip_forces: Sequence[float | None] | None,
    gratings: int,
) -> NDArray[np.float64] | None:
    """The tip loads (N) of the loading rows (as :func:`loading_rows` picks them); None without
    a tip grating or where a loading row has no finite load."""
    if not tip_forces or len(tip_forces) != len(rows):
        return None
    picked = [
        math.nan if f is None else float(f)
        for (state, advance, strains), f in zip(rows, tip_forces, strict=True)
        if row_in(state, advance, strains, LOADING_STATES, gratings)
    ]
    tip = np.asarray(picked, dtype=np.float64)
    return tip if tip.size and np.all(np.isfinite(tip)) else None
