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
from ..corrections import ContactLaw
from .grid import grid_fits

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


def contradictions(
    belief: Belief,
    law: ContactLaw,
    base: tuple[FloatArray, FloatArray],
    P: FloatArray,
    window: tuple[float, float],
    offset: bool,
    scale2: float,
) -> tuple[str, ...]:
    """The warning (none or one) that the record prefers an alternative to the stated point
    belief by more than MARGIN. ``base`` is the estimate's (depth base, weights), ``window``
    the contact positions (m) to search, ``scale2`` the noise model's s^2."""
    alts = alternatives(belief, law)
    if not alts:
        return ()
    depth_base, w = base
    grid = np.linspace(window[0], window[1], CHECK_POINTS)
    laws = [law, *(alt for _, alt in alts)]
    best = [float(np.min(_rss(candidate, depth_base, P, w, grid, offset))) for candidate in laws]
    gains = [(best[0] - rss) / scale2 for rss in best[1:]]
    k = int(np.argmax(gains))
    if gains[k] <= MARGIN:
        return ()
    return (
        f"{CONTRADICTED} belief: the record prefers {alts[k][0]}: delta chi^2 = {gains[k]:.0f}",
    )


def _rss(
    law: ContactLaw,
    depth_base: FloatArray,
    P: FloatArray,
    w: FloatArray,
    grid: FloatArray,
    offset: bool,
) -> FloatArray:
    """The weighted RSS at every contact position of ``grid`` (E, P0 in closed form), refined
    on a finer grid around its minimum."""
    ((E, _, rss, _),) = grid_fits([law], depth_base, P, w, grid, offset)
    rss = np.where(E > 0.0, rss, np.inf)
    i = int(np.argmin(rss))
    step = grid[1] - grid[0] if grid.size > 1 else 0.0
    fine = np.linspace(grid[i] - step, grid[i] + step, 21)
    ((E2, _, rss2, _),) = grid_fits([law], depth_base, P, w, fine, offset)
    return np.concatenate([rss, np.where(E2 > 0.0, rss2, np.inf)])
