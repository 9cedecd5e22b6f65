"""The world's tissue from finite elements: a rigid sphere indenting an elastic layer.

Import cost matters here: this package and :mod:`sim.fem.law` / :mod:`sim.fem.table` do not
import scikit-fem (about 1 s); only a table that must be solved loads the solver.
See docs/tissue-fe.md.
"""

from __future__ import annotations

from .law import FeTissueLaw
from .problem import LayerProblem
from .table import ForceTable, load_table, table_key

__all__ = ["FeTissueLaw", "ForceTable", "LayerProblem", "load_table", "table_key"]
