"""One relaxed modulus per sample from its trials' relaxation fits (issue 41).

A relaxing sample's pooled elastic fit (``estimation.jointfit.pooling``) is an apparent modulus
at the indentation speed, and the belief check on its pooled elastic record blames the
relaxation on the thickness. Its answer is the relaxed modulus. Each trial's relaxed interval is
mostly what every trial of the sample shares: the envelope over the belief's open hypotheses
and the law's model-form bound (``estimation.relaxation.beliefs``), which do not shrink with the
number of trials; the noise's share is small (a tip grating's load). So the sample's number is
the median of its trials' and its interval the typical trial's half-widths (the medians of each
side's) around it: no narrower than one trial's, robust to one odd trial::

    fit = pool_relaxed([o.relaxation for o in outcomes if o.relaxation is not None])
    fit.modulus, fit.ci_low, fit.ci_high
"""

from __future__ import annotations

import statistics
from collections.abc import Sequence

from ..jointfit.pooling import PooledFit
from .result import RelaxationFit


def pool_relaxed(fits: Sequence[RelaxationFit]) -> PooledFit:
    """The sample's relaxed modulus (Pa) and interval from at least two trials' fits."""
    done = [f for f in fits if f.success and None not in (f.relaxed, f.relaxed_low, f.relaxed_high)]
    if len(done) < 2:
        return PooledFit(len(done), message=f"{len(done)} relaxed fit(s): pooling needs 2")
    centre = statistics.median(float(f.relaxed or 0.0) for f in done)
    down = statistics.median(float((f.relaxed or 0.0) - (f.relaxed_low or 0.0)) for f in done)
    up = statistics.median(float((f.relaxed_high or 0.0) - (f.relaxed or 0.0)) for f in done)
    return PooledFit(len(done), centre, max(centre - down, 0.0), centre + up)
