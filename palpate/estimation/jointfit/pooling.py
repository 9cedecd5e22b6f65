"""One answer per sample: every trial of a sample fitted together (issue 41).

The paper reports per sample (Table I); a campaign presses each sample several times, at
several depths, with several tubes. Each trial's joint fit keeps its share of a pooled fit
(:class:`Terms`): for the estimate's law, its other model form and each alternative to a stated
point belief (``beliefcheck.alternatives``), on the trial's grid of contact positions x0, the
closed-form E(x0), the weighted RSS(x0) and its curvature S(x0) in E, both in noise variances
(divided by the trial's s^2). With P0 profiled out, the trial's chi^2 at a modulus E is::

    q_k(E) = min over x0 of [RSS_k(x0) + S_k(x0) (E - E_k(x0))^2]

(each trial keeps its own contact point and load offset), and the sample's, for one law (one
shared hypothesis of thickness, base and Poisson ratio), is the sum over its trials. The pooled
estimate minimises it; its interval is the profile-likelihood region ``X(E) <= X_min +
chi2_1(confidence)`` of each model form, their envelope, widened by the trials' largest
model-form bound (a bias of unknown sign: it does not average out over trials) as one trial's
is (``modelform.widened``).

The pooled belief check: an alternative's pooled chi^2 against the stated belief's, both at
their best modulus. The trials of one sample span depths (and so delta/h) that a single trial
does not, and a shared modulus must explain them all: a wrong thickness, base or Poisson ratio
shows as a pooled misfit the stated law cannot absorb::

    pooled = pool([o.joint.terms for o in outcomes if o.joint is not None and o.joint.terms])
    pooled.modulus, (pooled.ci_low, pooled.ci_high), pooled.contradiction
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.special import gammaincinv  # type: ignore[import-untyped,unused-ignore]

from .modelform import widened

FloatArray = NDArray[np.float64]

STATED = "stated"
FORM = "form"
E_POINTS = 801
KEEP = 400.0  # chi^2 above a curve's minimum beyond which its contact positions are dropped
E_SPAN = 0.6  # the grid spans the trials' estimates +- this in log E (and at least +-60 %)
POOLED_MARGIN = 9.0
"""pooled delta chi^2 beyond which a stated point belief counts as contradicted (one trial's
margin, ``beliefcheck.MARGIN``): on 190 samples with true beliefs (seeds 0-4 of six scenes,
docs/estimation.md) the largest was 7 (S7 of the robot campaign, seed 0: ten neo-Hookean
trials), the next 3.5."""


@dataclass(frozen=True)
class Curve:
    """One law on one trial's grid of contact positions: E(x0) (Pa), RSS(x0) and S(x0), in
    noise variances (S per Pa^2)."""

    E: FloatArray
    rss: FloatArray
    S: FloatArray

    def trimmed(self) -> Curve:
        """The contact positions that can matter: finite RSS within ``KEEP`` of its minimum
        (a row further up lies above every chi^2 the pooled fit reads)."""
        keep = np.isfinite(self.rss) & (self.rss <= np.min(self.rss) + KEEP)
        return Curve(self.E[keep], self.rss[keep], self.S[keep])

    def as_dict(self) -> dict[str, list[float]]:
        return {"E": self.E.tolist(), "rss": self.rss.tolist(), "S": self.S.tolist()}

    @classmethod
    def from_dict(cls, d: dict[str, list[float]]) -> Curve:
        return cls(*(np.asarray(d[k], dtype=np.float64) for k in ("E", "rss", "S")))

    def chi2(self, moduli: FloatArray) -> FloatArray:
        """min over x0 of RSS + S (E - E(x0))^2 at each of ``moduli`` (Pa)."""
        d = moduli[None, :] - self.E[:, None]
        out: FloatArray = np.min(self.rss[:, None] + self.S[:, None] * d * d, axis=0)
        return out


@dataclass(frozen=True)
class Terms:
    """A trial's share of its sample's pooled fit: its estimate, its model-form bound and a
    :class:`Curve` per law, keyed ``"stated"`` (the estimate's law), ``"form"`` (its other
    layer ratio, when there is one) and each alternative's sentence (``beliefcheck``)."""

    modulus: float
    model_form: float
    curves: dict[str, Curve] = field(default_factory=dict)

    def as_dict(self) -> dict[str, object]:
        """JSON-ready (the trial log's estimate record carries it, for a resumed campaign)."""
        return {
            "modulus": self.modulus,
            "model_form": self.model_form,
            "curves": {k: c.as_dict() for k, c in self.curves.items()},
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Terms:
        curves = {k: Curve.from_dict(c) for k, c in d["curves"].items()}
        return cls(float(d["modulus"]), float(d["model_form"]), curves)


@dataclass(frozen=True)
class PooledFit:
    """A sample's pooled estimate (Pa) and interval, the trials pooled, the pooled belief check
    (the alternative the record prefers and by how much, or None) and why there is no number."""

    trials: int
    modulus: float | None = None
    ci_low: float | None = None
    ci_high: float | None = None
    contradiction: str | None = None
    gains: dict[str, float] = field(default_factory=dict)
    message: str = "ok"

    def covers(self, modulus: float) -> bool:
        return (
            self.ci_low is not None
            and self.ci_high is not None
            and (self.ci_low <= modulus <= self.ci_high)
        )


def pool(terms: Sequence[Terms], confidence: float = 0.95) -> PooledFit:
    """The sample's pooled fit from its trials' :class:`Terms` (at least two)."""
    if len(terms) < 2:
        return PooledFit(len(terms), message=f"{len(terms)} trial(s) with a fit: pooling needs 2")
    centre = float(np.exp(np.median([math.log(t.modulus) for t in terms])))
    spread = max(abs(math.log(t.modulus / centre)) for t in terms)
    half = max(E_SPAN, 1.5 * spread)
    moduli = centre * np.exp(np.linspace(-half, half, E_POINTS))
    totals = _totals(terms, moduli)
    stated = totals[STATED]
    i = int(np.argmin(stated))
    if i in (0, E_POINTS - 1):
        return PooledFit(len(terms), message="the pooled minimum lies at the grid's edge")
    E_hat = float(moduli[i])
    level = chi2_quantile(confidence)
    lows, highs = [], []
    for key in (STATED, FORM):
        curve = totals.get(key)
        if curve is None:
            continue
        inside = moduli[curve <= curve.min() + level]
        lows.append(float(inside.min()))
        highs.append(float(inside.max()))
    eps = max(t.model_form for t in terms)
    lo, hi = widened(E_hat, min(*lows, E_hat), max(*highs, E_hat), eps)  # holds the estimate
    alts = {k: v for k, v in totals.items() if k not in (STATED, FORM)}
    gains = {k: float(stated.min() - v.min()) for k, v in alts.items()}
    # an alternative contradicts the belief when the record prefers it beyond the margin and
    # it would move the answer out of the interval (within it, the answer holds either way)
    moved = {k: float(moduli[int(np.argmin(v))]) for k, v in alts.items()}
    against = [k for k in alts if gains[k] > POOLED_MARGIN and not lo <= moved[k] <= hi]
    contradiction = None
    if against:
        k = max(against, key=lambda key: gains[key])
        contradiction = (
            f"the pooled record of {len(terms)} trials prefers {k}: delta chi^2 = "
            f"{gains[k]:.0f}, and {moved[k] / 1e3:.4g} kPa under it (outside the interval)"
        )
    return PooledFit(len(terms), E_hat, lo, hi, contradiction, gains)


def chi2_quantile(p: float) -> float:
    """chi^2(1)'s quantile at probability ``p``, as scipy.stats computes it (2 gammaincinv(1/2,
    p)) without stats' 0.4 s import on every process that estimates."""
    return float(2.0 * gammaincinv(0.5, p))


def _totals(terms: Sequence[Terms], moduli: FloatArray) -> dict[str, FloatArray]:
    """Per law key, the sum over the trials that have it of their chi^2 curves; a key only
    some trials carry (an alternative one trial could not fit) is left out."""
    keys = set.intersection(*(set(t.curves) for t in terms))
    return {k: np.sum([t.curves[k].chi2(moduli) for t in terms], axis=0) for k in keys}
