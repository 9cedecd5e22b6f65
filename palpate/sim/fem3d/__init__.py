"""The world's tissue in three dimensions: a layer holding spherical inclusions.

A rigid sphere indents the layer's surface; stiff (or soft) spheres inside the layer change
the force. The layer's surface compliance over the patch the tip can touch comes from one
factorisation of a trilinear finite-element model (a quarter or a half of it where the
geometry is symmetric), after which every depth is a small complementarity problem. The world
uses the inclusions' effect as a factor on the validated axisymmetric table. See
docs/inclusions.md. scipy only (no scikit-fem); ``estimation`` imports nothing of it.
"""

from __future__ import annotations

from .problem import Inclusion, InclusionProblem
from .table import RatioTable, load_ratios, ratio_key
from .world import InclusionWorld

__all__ = [
    "Inclusion",
    "InclusionProblem",
    "InclusionWorld",
    "RatioTable",
    "load_ratios",
    "ratio_key",
]
