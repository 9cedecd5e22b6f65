"""Quasi-static equilibrium of the sensor beam pressed on tissue, along the sensor axis.

After contact, a stage advance ``u`` (m) splits into tissue indentation ``delta``, beam end
shortening ``e`` and, when the tube tip is compliant, tube-tip deflection ``P / k_tube``::

    u = delta + e + P / k_tube,        F_tissue(delta) = P_beam(e) = P

The beam law is an ``estimation.beam.model.Beam`` (pre-buckling ``EA e / L``, then the extensible
clamped-pinned elastica) or an :class:`AxialLaw` built around any ``force(e)`` callable.

How it is solved (and why). ``u(e)`` is increasing on the rising branch, but near the buckling
plateau ``P`` barely changes while ``e`` grows, so the unknown is never ``P``:

- before the onset (``u <= u_onset``, all compression of the straight beam) the beam side is
  explicit in ``P``: ``e_b(P) = P L / EA`` (+ the imperfection's geometric shortening), so the
  unknown is ``delta`` and ``q(delta) = delta + e_b(F(delta)) + F(delta)/k - u`` is convex and
  increasing: Newton started right of the root converges monotonically, no inner solve;
- after the onset the unknown is ``e`` in the bracket ``[e_cr, u - delta_onset - P_onset/k]``
  (``P >= P_onset`` there, so the right end is never left of the root), solved by the
  Anderson-Bjorck bracketing secant; ``P`` is nearly constant, so ``h(e)`` is nearly linear
  with slope ~1 and 2-4 steps suffice.

Everything is elementwise on arrays shaped like ``u``: a whole trial's stage positions solve in
one call. A single position (scalar ``u``, scalar law) takes a plain-float twin of the same two
stages. Failures are reported per element (``converged``) and overall (``success``,
``status``, ``message``), never as NaN.

Modules: :mod:`.law` (what goes in: :class:`AxialLaw`, :class:`ContactEffects`),
:mod:`.state` (what comes out: :class:`ContactState`, ``STATUS_MESSAGES``), :mod:`.sides` (the
beam with the tube and the imperfection folded in, and the tissue, on arrays; the imperfection
model is described there), :mod:`.arrays` (the vectorised two-stages), :mod:`.scalar` (their
plain-float twin), :mod:`.solve` (:func:`solve_contact`: checks and dispatch).
"""

from .law import (
    DEFAULT_MAX_E_OVER_L,
    AxialLaw,
    BeamLike,
    ContactEffects,
    ForceLaw,
    TissueLaw,
    axial_law,
)
from .solve import solve_contact
from .state import STATUS_MESSAGES, ContactState

__all__ = [
    "DEFAULT_MAX_E_OVER_L",
    "STATUS_MESSAGES",
    "AxialLaw",
    "BeamLike",
    "ContactEffects",
    "ContactState",
    "ForceLaw",
    "TissueLaw",
    "axial_law",
    "solve_contact",
]
