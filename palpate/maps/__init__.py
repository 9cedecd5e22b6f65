"""Stiffness maps: where the stiff tissue is, from many probes (issue 40).

``probes`` (a probe's number, interval and verdict), ``gp`` (the Gaussian process of log E over
the patch), ``region`` (the region above a threshold, the inclusion's centre and radius with
intervals, or "no inclusion found"), ``sampling`` (raster, random and active plans). Pure: no
simulator, no hardware; ``palpate.campaigns.survey`` runs a survey with them. docs/maps.md.

    >>> patch = Patch(-10e-3, -10e-3, 10e-3, 10e-3)       # m
    >>> [(round(x * 1e3, 2), round(y * 1e3, 2)) for x, y in raster_points(patch, 9)[:3]]
    [(-6.67, -6.67), (0.0, -6.67), (6.67, -6.67)]
"""

from __future__ import annotations

from .gp import MapError, Patch, StiffnessMap
from .probes import Probe
from .region import MapSummary, summarise
from .sampling import STRATEGIES, Active, Planned, plan_for, raster_points

__all__ = [
    "STRATEGIES",
    "Active",
    "MapError",
    "MapSummary",
    "Patch",
    "Planned",
    "Probe",
    "StiffnessMap",
    "plan_for",
    "raster_points",
    "summarise",
]
