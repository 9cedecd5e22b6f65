"""How deep an inclusion lies, how large and how stiff: the probes about it, read against a
buried sphere's share of the strain energy under the tip.

A probe reads the modulus through the strain energy its contact stores. A sphere of contrast c
under the surface changes the force by the share s of that energy it holds. How s falls with
the probe's offset from the sphere and grows with the contact's radius a = sqrt(R delta) depends
on how deep the sphere lies and how large it is, so the probes about an inclusion (their
offsets, their contact radii and their moduli) place it in depth. The model, written here and
not taken from the world (``sim.fem3d`` solves finite elements):

- the energy density of the tip's field is the incompressible Boussinesq point load's (a radial
  stress ~ cos(theta) / r^2), its source set a height ``b`` above the surface so that the
  contact's width smooths it: ``u ~ Z^2 / (rho^2 + Z^2)^3`` with ``Z = z + b``, whose integral
  over the half-space is ``pi / (2 b)``, with ``b = KAPPA a``;
- ``s`` is its integral over the sphere (a fixed quadrature of the unit ball), over that;
- the modulus's factor is Eshelby's dilute sphere, ``1 + GAIN s (c - 1) / (1 + BETA (c - 1))``
  (BETA is 0.4 for an incompressible sphere in an incompressible matrix).

KAPPA, GAIN and BETA were fitted to the finite-element world's factor for one patch of four
spheres (tops 0.5-2.5 mm, radii 2-3.5 mm, 0.3x to 8x; offsets 0-4 mm; depths of indentation
0.05-1.3 mm under the 3.5 mm tip): 2.7 % rms in log E. On a second patch of four others it is
4.2 % (:data:`MODEL_SD`, added to every probe's own sd). ``bench/depth_model.py`` fits and
checks them. docs/maps.md, "Depth".

Depth is read from the lateral profile, not from how each record's modulus changes with the
indentation: the joint fit's free contact point absorbs that change (a modulus that rises with
depth looks like a later contact), so the loading's first half reads the whole's modulus to
within 0.01 over every inclusion of a study (docs/maps.md).

The fit: each usable probe within :data:`REACH` contact radii of the centre and nearer to it
than to any other inclusion gives log E at its contact radius. Top depth, radius (both on grids
scaled by the probes' median contact radius) and contrast (stiff above one, soft below) are
gridded; an offset of the background in log E is profiled in closed form, with a prior sd of
:data:`BACKGROUND_SD` about the map's background (the map's is the median over the whole patch,
which large inclusions lift). Intervals are profile-likelihood: the grid values whose best
chi^2 lies within 3.84 s^2 of the least, s^2 the reduced chi^2 where above one; the values
are the least's grid point (top and radius up to 3.5 median contact radii). Depth and radius
trade off, so their intervals are wide where the probes cannot tell them apart; an
interval that reaches its grid's end says that the probes bound the value on one side only
(:attr:`DepthReading.open`)::

    reading = read_depth(stiffness_map.used, centre=(4e-3, -4e-3),
                         background=stiffness_map.background, kind="stiff")
    reading.depth, reading.depth_ci          # the centre's depth (m) and its 95 % interval
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .probes import Probe

FloatArray = NDArray[np.float64]
Interval = tuple[float, float]

KAPPA = 0.766  # the source's height over the surface, in contact radii
GAIN = 2.058  # the share's weight on the force
BETA = 0.366  # Eshelby's strain concentration: (c - 1) / (1 + BETA (c - 1))
MODEL_SD = 0.042  # the model's error in log E on the patch it was not fitted to
BACKGROUND_SD = 0.1  # prior sd of the background's offset from the map's (log E)
REACH = 4.5  # probes within this many contact radii of the centre are read
MIN_PROBES = 5  # fewer usable probes about an inclusion: no reading
CHI2_95 = 3.841458820694124  # one degree of freedom

TOPS = np.linspace(0.05, 3.5, 50)  # top depths, in median contact radii
RADII = np.linspace(0.5, 3.5, 21)  # radii, in median contact radii
CONTRASTS = {
    "stiff": np.geomspace(1.1, 50.0, 40),
    "soft": np.geomspace(0.02, 0.95, 30),
}


def _unit_ball(shells: int = 8, directions: int = 96) -> tuple[FloatArray, FloatArray]:
    """Points of the unit ball and their volume shares (summing to one): shells of equal
    thickness at their volume-mean radii, each with Fibonacci directions."""
    k = np.arange(directions) + 0.5
    polar = np.arccos(1.0 - 2.0 * k / directions)
    azimuth = math.pi * (1.0 + math.sqrt(5.0)) * k
    unit = np.stack(
        [np.cos(azimuth) * np.sin(polar), np.sin(azimuth) * np.sin(polar), np.cos(polar)], axis=1
    )
    edges = np.linspace(0.0, 1.0, shells + 1)
    volume = edges[1:] ** 3 - edges[:-1] ** 3
    radius = ((edges[:-1] ** 3 + edges[1:] ** 3) / 2.0) ** (1.0 / 3.0)
    points = (radius[:, None, None] * unit[None, :, :]).reshape(-1, 3)
    return points, np.repeat(volume / directions, directions)


BALL, BALL_WEIGHTS = _unit_ball()


def energy_share(
    offset: FloatArray, contact_radius: FloatArray, top: FloatArray, radius: float
) -> FloatArray:
    """The share of the tip's strain energy a sphere of ``radius`` holds, its top ``top`` under
    the surface, for probes ``offset`` from its axis with ``contact_radius`` (lengths in the
    probes' median contact radius; ``top`` (T,), the probes' arrays (N,)): a (T, N) array.

    >>> float(energy_share(np.array([0.0]), np.array([1.0]), np.array([0.5]), 2.0)[0, 0])
    0.2...
    """
    x = BALL * radius
    rho2 = (x[:, 0, None] + offset[None, :]) ** 2 + x[:, 1, None] ** 2  # (Q, N)
    source = KAPPA * contact_radius  # (N,)
    z = top[:, None, None] + radius + x[None, :, 2, None] + source[None, None, :]  # (T, Q, N)
    density = z**2 / (rho2[None] + z**2) ** 3
    volume = 4.0 / 3.0 * math.pi * radius**3
    shares: FloatArray = np.einsum("q,tqn->tn", BALL_WEIGHTS, density)
    return shares * volume * (2.0 * source / math.pi)


def modulus_factor(share: FloatArray, contrast: float | FloatArray) -> FloatArray:
    """The apparent modulus over the background's for a share of the energy in a sphere of
    ``contrast`` (Eshelby's dilute concentration), kept above a thousandth."""
    excess = contrast - 1.0
    return np.maximum(1.0 + GAIN * share * excess / (1.0 + BETA * excess), 1e-3)


@dataclass(frozen=True)
class DepthReading:
    """An inclusion's sphere, read from the probes about it (m; 95 % intervals).

    Attributes:
        depth, depth_ci: its centre's depth under the surface.
        top, top_ci: its top's depth.
        radius, radius_ci: the sphere's radius.
        contrast, contrast_ci: its modulus over the background's.
        probes: how many probes were read.
        support: how much better a sphere explains them than the background alone (the drop
            in chi^2 over s^2): under :data:`CHI2_95`, the probes about it do not need one.
        open: the names of the intervals that reach an end of their grid the tissue does not
            set (the top's deepest, either end of radius and contrast; the centre's depth with
            either of the first two): the probes bound these on one side only.
    """

    depth: float
    depth_ci: Interval
    top: float
    top_ci: Interval
    radius: float
    radius_ci: Interval
    contrast: float
    contrast_ci: Interval
    probes: int
    support: float
    open: tuple[str, ...] = ()

    @property
    def needed(self) -> bool:
        """Whether the probes about it need a sphere at 95 % (one degree of freedom: its
        strength; where there is none, its place and size are not defined)."""
        return self.support >= CHI2_95

    def as_dict(self) -> dict[str, object]:
        mm = 1e3
        return {
            "depth_mm": self.depth * mm,
            "depth_ci_mm": [v * mm for v in self.depth_ci],
            "top_depth_mm": self.top * mm,
            "top_depth_ci_mm": [v * mm for v in self.top_ci],
            "sphere_radius_mm": self.radius * mm,
            "sphere_radius_ci_mm": [v * mm for v in self.radius_ci],
            "contrast": self.contrast,
            "contrast_ci": list(self.contrast_ci),
            "depth_probes": self.probes,
            "depth_open": list(self.open),
            "depth_support": self.support,
        }


def nearby(
    probes: Sequence[Probe],
    centre: tuple[float, float],
    others: Sequence[tuple[float, float]] = (),
) -> list[Probe]:
    """The usable probes with a contact radius within :data:`REACH` contact radii of
    ``centre`` and no nearer any of ``others``."""
    out = []
    for p in probes:
        if not p.usable or p.contact_radius is None:
            continue
        d = math.hypot(p.x - centre[0], p.y - centre[1])
        if d > REACH * p.contact_radius:
            continue
        if any(math.hypot(p.x - ox, p.y - oy) < d for ox, oy in others):
            continue
        out.append(p)
    return out


def read_depth(
    probes: Sequence[Probe],
    centre: tuple[float, float],
    background: float,
    kind: str,
    others: Sequence[tuple[float, float]] = (),
) -> DepthReading | None:
    """The sphere under ``centre`` (m) from ``probes`` (``background``: the map's log E;
    ``kind``: ``"stiff"`` or ``"soft"``; ``others``: the other inclusions' centres, whose
    probes are left to them). None with fewer than :data:`MIN_PROBES` usable probes about it."""
    if kind not in CONTRASTS:
        raise ValueError(f"kind must be one of {sorted(CONTRASTS)}, got {kind!r}")
    near = nearby(probes, centre, others)
    if len(near) < MIN_PROBES:
        return None
    radii = np.array([p.contact_radius for p in near], dtype=np.float64)
    scale = float(np.median(radii))
    offset = np.array([math.hypot(p.x - centre[0], p.y - centre[1]) for p in near]) / scale
    logs = np.log([p.modulus for p in near]) - background  # type: ignore[arg-type]
    weight = 1.0 / (np.array([p.log_sigma() for p in near]) ** 2 + MODEL_SD**2)
    chi = _chi2(offset, radii / scale, logs, weight, CONTRASTS[kind])  # (T, R, C)
    alone = float(_shifted_misfit(logs, weight))  # no sphere: the background's shift alone
    return _reading(chi, alone, CONTRASTS[kind], scale, len(near))


def _shifted_misfit(residual: FloatArray, weight: FloatArray) -> FloatArray:
    """chi^2 of ``residual`` (probes on the last axis) less the background's offset that
    minimises it under a Gaussian prior of :data:`BACKGROUND_SD` (closed form), the prior's
    term included."""
    prior = 1.0 / BACKGROUND_SD**2
    shift = (residual * weight).sum(axis=-1) / (weight.sum() + prior)
    misfit = ((residual - shift[..., None]) ** 2 * weight).sum(axis=-1) + shift**2 * prior
    return np.asarray(misfit, dtype=np.float64)


def _chi2(
    offset: FloatArray,
    contact: FloatArray,
    logs: FloatArray,
    weight: FloatArray,
    contrasts: FloatArray,
) -> FloatArray:
    """chi^2 over the grid of top depth, radius and contrast, the background's offset profiled
    (a Gaussian prior of :data:`BACKGROUND_SD`)."""
    chi = np.empty((TOPS.size, RADII.size, contrasts.size))
    for j, radius in enumerate(RADII):
        share = energy_share(offset, contact, TOPS, float(radius))  # (T, N)
        residual = logs - np.log(modulus_factor(share[None], contrasts[:, None, None]))
        chi[:, j, :] = _shifted_misfit(residual, weight).T  # (C, T) -> (T, C)
    return chi


def _reading(
    chi: FloatArray, alone: float, contrasts: FloatArray, scale: float, n: int
) -> DepthReading:
    """The best grid point and the profile intervals of top, centre depth, radius, contrast;
    ``alone``: chi^2 without a sphere."""
    least = float(chi.min())
    s2 = max(1.0, least / max(n - 4, 1))
    inside: NDArray[np.bool_] = np.asarray(chi <= least + CHI2_95 * s2)
    tops = TOPS * scale
    radii = RADII * scale
    centres = tops[:, None] + radii[None, :]
    held: NDArray[np.bool_] = np.any(inside, axis=2)  # (T, R)
    opened: list[str] = []

    def span(name: str, values: FloatArray, kept: NDArray[np.bool_], low: bool = True) -> Interval:
        lo, hi = float(values[kept].min()), float(values[kept].max())
        if (low and lo <= values.min()) or hi >= values.max():
            opened.append(name)
        return lo, hi

    # a top at the grid's first value is at the surface, a bound the tissue sets
    top_ci = span("top", tops, np.any(held, axis=1), low=False)
    radius_ci = span("radius", radii, np.any(held, axis=0))
    contrast_ci = span("contrast", contrasts, np.any(inside, axis=(0, 1)))
    depth_ci = (float(centres[held].min()), float(centres[held].max()))
    if "top" in opened or "radius" in opened:
        opened.insert(0, "depth")
    i, j, k = (int(v) for v in np.unravel_index(int(np.argmin(chi)), chi.shape))
    top, radius, contrast = float(tops[i]), float(radii[j]), float(contrasts[k])
    return DepthReading(
        depth=top + radius,
        depth_ci=depth_ci,
        top=top,
        top_ci=top_ci,
        radius=radius,
        radius_ci=radius_ci,
        contrast=contrast,
        contrast_ci=contrast_ci,
        probes=n,
        support=(alone - least) / s2,
        open=tuple(opened),
    )
