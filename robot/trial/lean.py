"""The load's lean measured on a trial's record (``estimation.misalignment``), trial and replay.

The rows before buckling (states approach, contact, indenting) with their exposed lengths go to
:func:`estimation.misalignment.measure_lean`; the rows after (``buckled``) are the elastica's,
which the lateral load's linear shape does not describe.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np
from numpy.typing import NDArray

from config.schema import SensorConfig
from estimation.misalignment import Lean, measure_lean
from estimation.section import Section

PRE_BUCKLING = frozenset({"approach", "contact", "indenting"})


def grating_spans_from_tip(sensor: SensorConfig) -> NDArray[np.float64]:
    """(G, 2): each used grating's (d0, d1), metres from the sensor tip."""
    centres = np.asarray(sensor.grating_centres_from_tip(), dtype=np.float64)
    half = sensor.grating_length / 2
    return np.stack([centres - half, centres + half], axis=1)


def lean_of_rows(
    rows: Iterable[tuple[str, float, Sequence[float]]],
    sensor: SensorConfig,
    section: Section,
    *,
    kind: str,
    exposed_length: float,
    flush_translation: float,
) -> Lean:
    """The lean from (state, advance, strains) rows: on the robot L = advance - flush
    translation, on the bench ``exposed_length``."""
    gratings = len(sensor.used_gratings)
    adv: list[float] = []
    eps: list[Sequence[float]] = []
    for state, advance, strains in rows:
        if state in PRE_BUCKLING and len(strains) == gratings:
            adv.append(advance)
            eps.append(strains)
    if not adv:
        return Lean(False, "no rows before buckling")
    x = np.asarray(adv, dtype=np.float64)
    lengths = np.asarray(
        x - flush_translation if kind == "robot" else np.full(x.size, exposed_length),
        dtype=np.float64,
    )
    return measure_lean(
        np.asarray(eps, dtype=np.float64).reshape(-1, gratings),
        lengths,
        grating_spans_from_tip(sensor),
        section.EA,
        section.EI,
        section.fiber_offset,
    )
