"""Step 5 of the joint fit: can the record contradict a stated point belief?

The operator states a layer's thickness, its base and its Poisson ratio; where one is stated as
a point (not a range the fit profiles over), the estimate trusts it. A wrong thickness moves the
estimate by 10-30 % and leaves the fit's own interval untouched. But the whole loading curve
carries shape information the single modulus does not use: a layer twice as thick bends the
force-depth curve differently. So the record is fitted once more under a few alternatives of
each stated property (thickness halved and doubled, the other base, nu +- 0.05), each at its
best contact position and modulus, with the estimate's frozen weights. If one fits better than
the stated belief by more than ``MARGIN`` in chi^2 (noise variances: ``delta chi^2 =
(RSS_stated - RSS_alt) / s^2``), the belief is contradicted and the verdict says so, with the
alternative and the margin.

What noise alone gives: the alternatives carry no extra parameter, so under a correct belief
``delta chi^2`` stays at or below 0 but for model error; the margin is set from the campaigns
with correct beliefs (docs/estimation.md: false alarms on the paper's, the layers' and the
nominal scenes, detection against the size of the mistake).
"""

from __future__ import annotations

import dataclasses

import numpy as np
from numpy.typing import NDArray

from ..belief import Belief
from ..contact.law import ContactLaw
from .envelope import other_forms
from .grid import GridFit, grid_fits
from .pooling import FORM, STATED, Curve

FloatArray = NDArray[np.float64]

MARGIN = 9.0
"""delta chi^2 beyond which a stated point belief counts as contradicted by the record."""
CHECK_POINTS = 81
POISSON_STEP = 0.05
CONTRADICTED = "the record contradicts the stated"


def alternatives(belief: Belief, law: ContactLaw) -> list[tuple[str, ContactLaw]]:
    """(what it says, law) of each alternative to the belief's point properties around
    ``law`` (the estimate's)."""
    out: list[tuple[str, ContactLaw]] = []
    if law.thickness is not None and belief.thickness[0] == belief.thickness[1]:
        h = law.thickness
        for factor in (0.5, 2.0):
            alt = dataclasses.replace(law, thickness=h * factor)
            out.append((f"a {h * factor * 1e3:.3g} mm layer to the stated {h * 1e3:.3g} mm", alt))
    if law.thickness is not None and len(belief.bonded) == 1:
        stated, other = ("bonded", "sliding") if law.bonded else ("sliding", "bonded")
        out.append(
            (
                f"a {other} base to the stated {stated} one",
                dataclasses.replace(law, bonded=not law.bonded),
            )
        )
    if belief.poisson[0] == belief.poisson[1]:
        for step in (-POISSON_STEP, POISSON_STEP):
            nu = min(0.5, max(0.0, law.poisson + step))
            if nu != law.poisson:
                alt = dataclasses.replace(law, poisson=nu)
                out.append((f"nu = {nu:.2g} to the stated {law.poisson:.2g}", alt))
    return out


def law_curves(
    belief: Belief,
    law: ContactLaw,
    base: tuple[FloatArray, FloatArray],
    P: FloatArray,
    window: tuple[float, float],
    offset: bool,
    scale2: float,
) -> dict[str, Curve]:
    """The record's :class:`pooling.Curve` (in noise variances) of the estimate's ``law``
    (``"stated"``), its other model form (``"form"``) and each alternative to the belief's
    point properties (keyed by its sentence), over the contact positions of ``window`` (m).
    ``base`` is the estimate's (depth base, weights), ``scale2`` the noise model's s^2."""
    depth_base, w = base
    grid = np.linspace(window[0], window[1], CHECK_POINTS)
    laws = [(STATED, law), *((FORM, f) for f in other_forms(law)), *alternatives(belief, law)]
    coarse = grid_fits([c for _, c in laws], depth_base, P, w, grid, offset)
    curves = {}
    for (key, candidate), fit in zip(laws, coarse, strict=True):
        E, rss, S = _refined(candidate, fit, (depth_base, P, w), grid, offset)
        curves[key] = Curve(E, rss / scale2, S / scale2)
    return curves


def contradictions(curves: dict[str, Curve]) -> tuple[str, ...]:
    """The warning (none or one) that the record prefers an alternative to the stated point
    belief (``law_curves``) by more than MARGIN in chi^2, each at its best contact position
    and modulus."""
    best = {key: float(np.min(c.rss)) for key, c in curves.items()}
    return contradiction({k: best[STATED] - v for k, v in best.items() if k not in (STATED, FORM)})


def contradiction(
    gains: dict[str, float], margin: float = MARGIN, record: str = "the record"
) -> tuple[str, ...]:
    """The warning (none or one) that ``record`` prefers the alternative of largest ``gains``
    (its delta chi^2 over the stated belief, keyed by its sentence) by more than ``margin``."""
    if not gains:
        return ()
    worst = max(gains, key=lambda k: gains[k])
    if gains[worst] <= margin:
        return ()
    return (f"{CONTRADICTED} belief: {record} prefers {worst}: delta chi^2 = {gains[worst]:.0f}",)


def _refined(
    law: ContactLaw,
    coarse: GridFit,
    record: tuple[FloatArray, FloatArray, FloatArray],
    grid: FloatArray,
    offset: bool,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """E, the weighted RSS (inf where E <= 0) and S at every contact position of ``grid``
    (``coarse``: the law's grid fit there, E and P0 in closed form), and on a finer grid around
    the RSS's minimum; ``record`` is (depth base, P, weights)."""
    depth_base, P, w = record
    E, _, rss, S = coarse
    rss = np.where(E > 0.0, rss, np.inf)
    i = int(np.argmin(rss))
    step = grid[1] - grid[0] if grid.size > 1 else 0.0
    fine = np.linspace(grid[i] - step, grid[i] + step, 21)
    ((E2, _, rss2, S2),) = grid_fits([law], depth_base, P, w, fine, offset)
    rss2 = np.where(E2 > 0.0, rss2, np.inf)
    return np.concatenate([E, E2]), np.concatenate([rss, rss2]), np.concatenate([S, S2])
