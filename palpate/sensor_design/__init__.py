"""Sensor design for a tissue modulus range: exposed length, wires, fiber and tip radius.

The paper's sensor buckles at P_cr = 1.35 N (L = 42 mm), which sinks its 3.5 mm sphere 0.5-1.3 mm
into its 300-1100 kPa phantoms (delta/R up to 0.36, past Hertz's range) and would sink it
centimetres into skin (~6 kPa) or brain (~1.8 kPa). The sensor has to be designed for the range.

The method in one line: the beam is a force limiter. It buckles at P_cr = 20.19 EI / L**2 and
the Hertz sphere then stops at the depth where the tissue pushes back as hard,

    delta_b(E) = (3/4 P_cr (1 - nu**2) / (E sqrt(R)))**(2/3),

so over [E_min, E_max] one sensor sees depths in the fixed ratio (E_max / E_min)**(2/3). The
design must fit that ratio between a ceiling (Hertz valid at E_min: delta/R <= 0.1 and a/h <= 0.1
with a = sqrt(R delta)) and a floor (measurable at E_max: delta >= 20 encoder counts). Those
checks need only P_cr and R. Two more need the elastica (``estimation.beam.elastica.fast``), through
the fiber's offset from the neutral axis:

- detection: a short post-buckling shortening e_det (5 % of the smallest delta, the bias that
  detection adds to delta) must bend the gratings well above the pre-buckling norm (the axial
  pre-load P_cr/EA on every grating) plus 6 sigma of FBG noise; a bare fiber (no wires, no
  offset) sees no bending strain and fails here;
- delta bias: the stage travel before detection that is not indentation (axial compression
  P_cr L/EA, e_det, and for a sensor bowed by w0/L the bending shortening while its load rises
  to 0.9 P_cr, c (w0/L)**2 L ((1 - x)**-2 - 1)) stays under 10 % of the smallest delta; the
  detector threshold is raised above the bowed beam's strain at 0.9 P_cr so it does not fire
  early;
- fiber strain: after e_det plus the post-buckling travel the peak fiber strain
  ``(|dy_fbg| + r_fbg) max|dtheta/ds| + P/EA`` stays below the fiber's limit.

Every check is a ratio ``margin`` >= 1 when it holds. The search is a plain grid (fibers x wire
counts x wire diameters x tip radii x exposed lengths, ~1.4e5 candidates, 0.4-1 s), vectorised
over all candidates. Among the feasible ones it picks the most central: the largest worst margin,
then the largest second-worst, and so on (leximin on the logs, rounded to 1 %), so the choice
does not sit on a constraint's edge. When nothing is feasible, the result says why: first a
sensor-independent test (no tip radius fits the depth ratio between ceiling and floor), then the
checks that the closest candidate fails.

Pure functions on floats and numpy arrays; SI units (m, N, Pa).

Layout: ``space`` (what can be built and what must hold: :class:`DesignSpace`,
:class:`DesignConstraints`, :class:`SensorDesign`), ``model`` (the physics of candidates,
vectorised over them: depths, strains, imperfection, the checks; :func:`evaluate_design` for one
sensor), ``search`` (the grid and the leximin choice: :func:`design_sensor`), ``results``
(:data:`CHECKS`, :class:`Check`, :class:`DesignEvaluation`, :class:`DesignResult`).

The paper's sensor's depths at the ends of its range (m): 1.6 mm at 300 kPa, 0.68 mm at 1.1 MPa::

    >>> [round(float(hertz_depth(1.35, e, 1.75e-3, 0.45)) * 1e3, 2) for e in (300e3, 1100e3)]
    [1.61, 0.68]
"""

from __future__ import annotations

from .model import evaluate_design, hertz_depth, imperfection_state
from .results import CHECKS, Check, DesignEvaluation, DesignResult
from .search import design_sensor
from .space import DesignConstraints, DesignSpace, SensorDesign

__all__ = [
    "CHECKS",
    "Check",
    "DesignConstraints",
    "DesignEvaluation",
    "DesignResult",
    "DesignSpace",
    "SensorDesign",
    "design_sensor",
    "evaluate_design",
    "hertz_depth",
    "imperfection_state",
]
