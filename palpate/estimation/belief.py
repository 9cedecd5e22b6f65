"""What the estimator is told about a sample and the rig, and the hypotheses it profiles over.

An operator rarely knows a phantom's layer thickness, its bonding or its Poisson ratio exactly,
and an uncalibrated tube or stage has an unknown compliance. A :class:`Belief` states each as a
value or a range (SI); the joint fit (``estimation.jointfit``) then profiles the likelihood over
a grid of :class:`Hypothesis` es spanning what the belief leaves open, so E's interval carries
these uncertainties besides the FBG noise.

The grids, and why they are shaped so:

Every grid is as fine as E's sensitivity requires: neighbouring hypotheses move E by about
E_STEP (2 %), less than E's statistical half-width, so the union of their intervals has no gap
between grid points (a coarser grid missed the truth between its points).

- Poisson's ratio: uniform, E_STEP apart in 1/(1 - nu^2) (E enters the law as E/(1 - nu^2),
  times a thin-layer bracket whose coefficients are smooth in nu).
- thickness: uniform in 1/h, because the thin-layer bracket is a series in chi = sqrt(R delta)/h,
  i.e. in 1/h, at most CHI_STEP apart in chi at the record's deepest point (the bracket then
  changes by about 2 %), from the range's thickest to its thinnest layer; ``unknown`` runs from
  the half-space (1/h = 0) to the thinnest layer the series covers there (chi = CHI_MAX).
- bonding: each allowed value.
- compliance (tube tip or stage, m/N): uniform, each step shifting the deepest indentation by
  E_STEP / 1.5 of itself at the largest load (E ~ delta^-1.5); a calibrated compliance is a
  value (or the calibration's interval), an uncalibrated one the range ``[0, c_max]``. It
  shifts the depth by c P (``delta = u - e - c P - x0``).

The hypotheses are the Cartesian product; the provisional one (the middle of every range) is
fitted first and gives the noise model, and the profile over all of them gives the estimate and
its interval. Cost: one profile grid per hypothesis and model form (``jointfit.profile``).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Literal

import numpy as np

from .contact.finite_strain.table import Tip
from .contact.law import CHI_MAX, ContactLaw, LayerLaw, Material

E_STEP = 0.02
CHI_STEP = 0.02
MAX_THICKNESS_POINTS = 51
MAX_POINTS = 25  # Poisson's ratio and compliance
RANGE_POINTS = 3  # a range before the record's depth and load are known

Range = tuple[float, float]


def _checked_range(name: str, r: Range, lo: float, hi: float) -> Range:
    a, b = float(r[0]), float(r[1])
    if not (lo <= a <= b <= hi) or math.isnan(a) or math.isnan(b):
        raise ValueError(f"{name} must be a range {lo} <= min <= max <= {hi}, got {r!r}")
    return a, b


@dataclass(frozen=True)
class Hypothesis:
    """One point of the belief's grid: the contact law and the rig's compliance (m/N)."""

    law: ContactLaw
    compliance: float = 0.0

    def describe(self) -> dict[str, object]:
        """JSON-ready: thickness (m, None = half-space), bonded, poisson, compliance (m/N), and
        for a neo-Hookean law its material and tip."""
        out: dict[str, object] = {
            "thickness": self.law.thickness,
            "bonded": self.law.bonded,
            "poisson": self.law.poisson,
            "compliance": self.compliance,
        }
        if self.law.material != "linear":
            out["material"] = self.law.material
            out["tip"] = self.law.tip
        return out

    @classmethod
    def described(
        cls, best: Mapping[str, object], tip_radius: float, layer_law: LayerLaw = "exact"
    ) -> Hypothesis:
        """The hypothesis a :meth:`describe` dict (a fit's ``best``, a log's) stands for; the
        tip radius (m) and the layer law are the estimator's."""
        thickness = best.get("thickness")
        law = ContactLaw(
            tip_radius,
            float(best.get("poisson", 0.45)),  # type: ignore[arg-type]
            None if thickness is None else float(thickness),  # type: ignore[arg-type]
            bool(best.get("bonded", True)),
            layer_law=layer_law,
            material=str(best.get("material", "linear")),  # type: ignore[arg-type]
            tip=str(best.get("tip", "frictionless")),  # type: ignore[arg-type]
        )
        return cls(law, float(best.get("compliance") or 0.0))  # type: ignore[arg-type]


@dataclass(frozen=True)
class Belief:
    """What the estimator is told (SI). A value is a range of zero width.

    Attributes:
        tip_radius: R (m).
        poisson: (min, max) Poisson's ratio, within [0, 0.5].
        thickness: (min, max) layer thickness (m) on a rigid base; max = inf reaches the
            half-space, (inf, inf) is a half-space, min = 0 is "as thin as the model allows"
            (``unknown``).
        bonded: the bonding values allowed: (True,), (False,) or (True, False).
        compliance: (min, max) compliance (m/N) between the stage encoder and the sensor's
            clamp (tube tip or stage).
        large_indentation: Sneddon's sphere (else Hertz).
        layer_ratio_from: the thin-layer ratio of the laws (``ContactLaw.layer_ratio_from``).
        layer_law: the laws' layer law (``ContactLaw.layer_law``): exact, or the series.
        material: the laws' material (``ContactLaw.material``): linear, or neo-Hookean.
        tips: the tip contacts allowed (``ContactLaw.tip``): ("frictionless",),
            ("sticking",) or both (friction unknown: profiled over, as the bonding is).
    """

    tip_radius: float
    poisson: Range = (0.45, 0.45)
    thickness: Range = (math.inf, math.inf)
    bonded: tuple[bool, ...] = (True,)
    compliance: Range = (0.0, 0.0)
    large_indentation: bool = True
    layer_ratio_from: Literal["published", "sphere"] = "published"
    layer_law: LayerLaw = "exact"
    material: Material = "linear"
    tips: tuple[Tip, ...] = ("frictionless",)

    def __post_init__(self) -> None:
        _checked_range("poisson", self.poisson, 0.0, 0.5)
        _checked_range("thickness", self.thickness, 0.0, math.inf)
        _checked_range("compliance", self.compliance, 0.0, math.inf)
        if not self.bonded or len(set(self.bonded)) != len(self.bonded):
            raise ValueError(f"bonded must list True and/or False once each, got {self.bonded!r}")
        if not self.tips or len(set(self.tips)) != len(self.tips):
            raise ValueError(
                f"tips must list frictionless and/or sticking once each, got {self.tips!r}"
            )
        if self.thickness[1] == 0.0:
            raise ValueError("thickness must allow a layer thicker than 0 m")
        ContactLaw(self.tip_radius, self.poisson[0])  # validates the tip radius

    @classmethod
    def from_law(cls, law: ContactLaw, compliance: float = 0.0) -> Belief:
        """The belief that is exactly ``law`` (and the compliance, m/N)."""
        h = math.inf if law.thickness is None else law.thickness
        return cls(
            law.tip_radius,
            (law.poisson, law.poisson),
            (h, h),
            (law.bonded,),
            (compliance, compliance),
            law.large_indentation,
            law.layer_ratio_from,
            law.layer_law,
            law.material,
            (law.tip,),
        )

    @property
    def open_keys(self) -> tuple[str, ...]:
        """The properties the belief leaves open (profiled over), by name."""
        out = []
        if self.thickness[0] != self.thickness[1]:
            out.append("thickness")
        if len(self.bonded) > 1:
            out.append("bonded")
        if len(self.profiled_tips) > 1:
            out.append("tip")
        if self.poisson[0] != self.poisson[1]:
            out.append("poisson")
        if self.compliance[0] != self.compliance[1]:
            out.append("compliance")
        return tuple(out)

    @property
    def profiled_tips(self) -> tuple[Tip, ...]:
        """The tips the hypotheses span: a linear law does not tell them apart, so one."""
        return self.tips if self.material != "linear" else self.tips[:1]

    def provisional(self) -> Hypothesis:
        """The middle of every range (the half-space for an open-ended thickness): the
        hypothesis fitted first, for the noise model."""
        inv = _inverse_thickness(self.thickness, None, self.tip_radius)
        return self._hypothesis(
            float(np.mean(inv)) if len(inv) > 1 else inv[0],
            self.bonded[0],
            0.5 * (self.poisson[0] + self.poisson[1]),
            0.5 * (self.compliance[0] + self.compliance[1]),
            self.tips[0],
        )

    def hypotheses(
        self, max_depth: float, max_force: float | None = None
    ) -> tuple[Hypothesis, ...]:
        """The grid (see the module docstring); ``max_depth`` (m) and ``max_force`` (N), the
        deepest indentation and the largest load of the provisional fit, set the grids'
        steps and the thinnest layer of an ``unknown`` thickness."""
        inv = _inverse_thickness(self.thickness, max_depth, self.tip_radius)
        c = self.compliance
        n_c = RANGE_POINTS
        if max_force is not None and max_depth > 0:
            n_c = _count(1.5 * (c[1] - c[0]) * max_force / max_depth / E_STEP)
        grid = itertools.product(
            inv, self.bonded, _poisson_points(self.poisson), _points(c, n_c), self.profiled_tips
        )
        return tuple(self._hypothesis(*point) for point in grid)

    def _hypothesis(
        self,
        inverse_thickness: float,
        bonded: bool,
        poisson: float,
        compliance: float,
        tip: Tip = "frictionless",
    ) -> Hypothesis:
        h = None if inverse_thickness <= 0.0 else 1.0 / inverse_thickness
        law = ContactLaw(
            self.tip_radius,
            poisson,
            h,
            bonded,
            self.large_indentation,
            self.layer_ratio_from,
            self.layer_law,
            self.material,
            tip,
        )
        return Hypothesis(law, compliance)


def _count(steps: float) -> int:
    """Grid points for a range ``steps`` E_STEPs wide: ends included, 2..MAX_POINTS."""
    return min(max(math.ceil(steps) + 1, 2), MAX_POINTS)


def _poisson_points(r: Range) -> tuple[float, ...]:
    """Poisson ratios uniform in log 1/(1 - nu^2), E_STEP apart at most."""
    if r[0] == r[1]:
        return (r[0],)
    y0, y1 = (-math.log(1.0 - nu * nu) for nu in r)
    ys = np.linspace(y0, y1, _count((y1 - y0) / E_STEP))
    inner = [math.sqrt(1.0 - math.exp(-y)) for y in ys[1:-1]]
    return (r[0], *inner, r[1])


def _points(r: Range, n: int) -> tuple[float, ...]:
    if r[0] == r[1]:
        return (r[0],)
    return tuple(float(x) for x in np.linspace(r[0], r[1], n))


def _inverse_thickness(r: Range, max_depth: float | None, tip_radius: float) -> tuple[float, ...]:
    """1/h grid points (1/m; 0 = half-space), CHI_STEP apart in chi at ``max_depth`` (m; None:
    the range's ends only). An open lower end (0) is the thinnest layer the series covers at
    ``max_depth`` (chi = CHI_MAX); without a depth it is left out."""
    lo, hi = r
    inv_lo = 0.0 if math.isinf(hi) else 1.0 / hi
    if lo == hi:
        return (inv_lo,)
    if lo > 0.0:
        inv_hi = 1.0 / lo
    elif max_depth is None or max_depth <= 0.0:
        return (inv_lo,)
    else:
        inv_hi = max(CHI_MAX / math.sqrt(tip_radius * max_depth), inv_lo)
    n = 2
    if max_depth is not None and max_depth > 0.0:
        span_chi = (inv_hi - inv_lo) * math.sqrt(tip_radius * max_depth)
        n = min(max(math.ceil(span_chi / CHI_STEP) + 1, 2), MAX_THICKNESS_POINTS)
    return tuple(float(x) for x in np.linspace(inv_lo, inv_hi, n))
