"""Buckling detection from grating strains: the paper's norm threshold and a CUSUM detector.

Both detectors work on strains of shape (N,) one sample at a time (``update``) or on a recorded
series of shape (n, N) at once (``first_alarm``, vectorised; same answer as streaming).

- :class:`NormThreshold` is the paper's rule: buckling when the Euclidean norm of the grating
  strains crosses a threshold. Simple, but the norm also sees what is common to all gratings:
  the pre-buckling axial compression P/EA (about 140 ue at P_cr for the paper's beam, i.e.
  ~240 ue of norm with three gratings) and any temperature drift, so its threshold must sit
  above those, which costs delay.
- :class:`CusumDetector` removes the common mode (axial strain, uniform temperature change), then
  projects the rest on the first buckling mode's grating pattern (:func:`first_mode_pattern`, a
  matched filter) and runs a two-sided CUSUM on it in units of the strain noise. Without a
  pattern it runs a one-sided CUSUM on the standardised squared norm of the differential strains.
  Its false-alarm rate is set by the noise model (``threshold``/``drift`` in noise units), not
  by the load.

Near onset the buckled strains grow like sqrt(e/L) (the elastica's curvature; see
:func:`first_mode_strains`), so once above noise both detectors fire within micrometres of stage
advance; what separates them is how close to the noise and to the axial load they can be set.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..beam.elastica.constants import MODE_SLOPE_INTEGRAL, X1

FloatArray = NDArray[np.float64]


# ---------------------------------------------------------------------------------------------
# The first buckling mode, linearised: an analytic test problem and the CUSUM's template.


def first_mode_pattern(intervals: ArrayLike, length: float) -> FloatArray:
    """Grating averages of L * curvature of the clamped-pinned first mode, unit slope amplitude.

    Small-deflection mode: theta(xi) = a (cos(b xi) + b sin(b xi) - 1), L kappa = a b (b cos(b xi)
    - sin(b xi)), xi = s / L, b = X1; averaged over each row ``(s0, s1)`` of ``intervals``
    (shape (N, 2), m) with the exact antiderivative. Returns shape (N,) for a = 1.
    """
    iv = np.asarray(intervals, dtype=np.float64)
    if iv.ndim != 2 or iv.shape[1] != 2 or not length > 0:
        raise ValueError(f"intervals must be (N, 2) and length > 0, got {iv.shape} and {length}")
    xi = iv / length
    width = xi[:, 1] - xi[:, 0]
    if np.any(width <= 0):
        raise ValueError("each interval must have s0 < s1")
    anti = X1 * np.sin(X1 * xi) + np.cos(X1 * xi)
    return np.asarray((anti[:, 1] - anti[:, 0]) / width, dtype=np.float64)


def first_mode_strains(
    e_over_L: ArrayLike, intervals: ArrayLike, length: float, fiber_offset: float
) -> FloatArray:
    """Grating-average strains (Eq. 3 and 12) of the first mode at end shortening e/L >= 0.

    First-order (small-deflection) elastica: the slope amplitude is a = sqrt(2 (e/L) / J), so
    strains grow like sqrt(e/L). Shape: e_over_L.shape + (N,). Accurate to a few per cent for
    e/L below about 1e-2; use ``estimation`` for the full elastica.
    """
    e = np.asarray(e_over_L, dtype=np.float64)
    if np.any(e < 0):
        raise ValueError("e_over_L must be >= 0")
    a = np.sqrt(2.0 * e / MODE_SLOPE_INTEGRAL)
    pattern = first_mode_pattern(intervals, length)
    return np.asarray(fiber_offset / length * a[..., None] * pattern, dtype=np.float64)


# ---------------------------------------------------------------------------------------------
# Detectors


class BucklingDetector(Protocol):
    """What the indentation state machine (``robot.indentation``) needs of a detector: decide,
    one sample of grating strains at a time, that the beam has buckled."""

    def reset(self) -> None:
        """Re-arm: forget every sample seen."""
        ...

    def update(
        self, strains: tuple[float, ...], advance: float | None = None, load: float | None = None
    ) -> bool:
        """Feed one sample of grating strains (N,), with the stage's ``advance`` (m) and the
        tip grating's ``load`` (N, None without one) for a detector that reads them
        (``estimation.detect.plateau``); True once buckling is detected."""
        ...


class Detector(BucklingDetector, Protocol):
    """A streaming buckling detector that also reads a recorded series (benchmarks, tests): feed
    strains (N,), read ``alarm``; ``first_alarm`` on (n, N) gives the streaming answer at once."""

    alarm: bool

    def update(
        self, strains: ArrayLike, advance: float | None = None, load: float | None = None
    ) -> bool: ...

    def first_alarm(self, strains: ArrayLike) -> int | None: ...


def _series(strains: ArrayLike) -> FloatArray:
    s = np.asarray(strains, dtype=np.float64)
    if s.ndim != 2 or s.shape[1] < 1:
        raise ValueError(f"strains must have shape (n, N), got {s.shape}")
    return s


@dataclass
class NormThreshold:
    """The paper's rule: alarm once ||strains||_2 > ``threshold`` (dimensionless strain)."""

    threshold: float
    alarm: bool = field(default=False, init=False)

    def __post_init__(self) -> None:
        if not self.threshold > 0:
            raise ValueError(f"threshold must be > 0, got {self.threshold}")

    def update(
        self, strains: ArrayLike, advance: float | None = None, load: float | None = None
    ) -> bool:
        if not self.alarm:
            self.alarm = bool(
                np.linalg.norm(np.asarray(strains, dtype=np.float64)) > self.threshold
            )
        return self.alarm

    def reset(self) -> None:
        self.alarm = False

    def first_alarm(self, strains: ArrayLike) -> int | None:
        """Index of the first sample of (n, N) ``strains`` that alarms, or None."""
        hits = np.flatnonzero(np.linalg.norm(_series(strains), axis=1) > self.threshold)
        return int(hits[0]) if hits.size else None


@dataclass
class CusumDetector:
    """CUSUM on common-mode-free strains, matched to the first mode when ``pattern`` is given.

    ``sigma``: strain noise per grating (dimensionless; wavelength noise / k'_eps).
    ``pattern``: (N,) expected strain pattern of buckling (e.g. :func:`first_mode_pattern`), sign
    irrelevant; None uses the squared norm of the differential strains instead.
    ``drift`` and ``threshold``: CUSUM reference value k and decision interval h, in units of the
    standardised statistic; None picks the defaults below. The in-control average run length is
    about exp(theta h), theta the root of E[exp(theta (z - k))] = 1:

    - with a pattern, z ~ N(0, 1): k = 1, h = 12, theta = 2k, ARL0 ~ 3e10 samples;
    - without, z = chi2_r scaled, exponential right tail (r = 2 for three gratings): k = 2,
      h = 20, theta ~ 0.94, ARL0 ~ 1e8 samples (k = 1, h = 12 would give only ~1e4).

    That is no false alarm in days at 1 kHz either way.
    """

    sigma: float
    pattern: FloatArray | None = None
    drift: float | None = None
    threshold: float | None = None
    reject_common_mode: bool = True
    alarm: bool = field(default=False, init=False)
    _upper: float = field(default=0.0, init=False, repr=False)
    _lower: float = field(default=0.0, init=False, repr=False)

    def __post_init__(self) -> None:
        if not self.sigma > 0:
            raise ValueError(f"sigma must be > 0, got {self.sigma}")
        if self.drift is None:
            self.drift = 1.0 if self.pattern is not None else 2.0
        if self.threshold is None:
            self.threshold = 12.0 if self.pattern is not None else 20.0
        if not (self.drift >= 0 and self.threshold > 0):
            raise ValueError("drift must be >= 0 and threshold > 0")
        if self.pattern is not None:
            p = np.asarray(self.pattern, dtype=np.float64)
            if p.ndim != 1:
                raise ValueError(f"pattern must have shape (N,), got {p.shape}")
            self.pattern = p

    def _projector(self, n: int) -> FloatArray:
        eye = np.eye(n, dtype=np.float64)
        return eye - 1.0 / n if self.reject_common_mode else eye

    def score(self, strains: ArrayLike) -> FloatArray:
        """Standardised statistic per sample, shape (...): N(0, 1)-like before buckling.

        With a pattern: the projection on the (common-mode-free, unit) pattern over sigma.
        Without: (||P eps||^2 / sigma^2 - r) / sqrt(2 r), r = rank of the projector P.
        """
        s = np.asarray(strains, dtype=np.float64)
        n = s.shape[-1]
        proj = self._projector(n)
        if self.pattern is not None:
            if self.pattern.shape != (n,):
                raise ValueError(f"pattern has shape {self.pattern.shape}, strains end in {n}")
            b = proj @ self.pattern
            norm = float(np.linalg.norm(b))
            if norm <= 1e-12 * float(np.linalg.norm(self.pattern)):
                raise ValueError("pattern has no differential (non common-mode) part")
            return np.asarray(s @ (b / norm) / self.sigma, dtype=np.float64)
        r = n - 1 if self.reject_common_mode else n
        if r < 1:
            raise ValueError("common-mode rejection needs at least two gratings")
        q = np.asarray(np.sum((s @ proj) ** 2, axis=-1), dtype=np.float64) / self.sigma**2
        return np.asarray((q - r) / math.sqrt(2.0 * r), dtype=np.float64)

    @property
    def two_sided(self) -> bool:
        return self.pattern is not None

    def update(
        self, strains: ArrayLike, advance: float | None = None, load: float | None = None
    ) -> bool:
        if self.alarm:
            return True
        z = float(self.score(np.asarray(strains, dtype=np.float64)))
        k, h = self._kh
        self._upper = max(0.0, self._upper + z - k)
        if self.two_sided:
            self._lower = max(0.0, self._lower - z - k)
        self.alarm = max(self._upper, self._lower) > h
        return self.alarm

    @property
    def _kh(self) -> tuple[float, float]:
        if self.drift is None or self.threshold is None:  # set in __post_init__
            raise RuntimeError("drift/threshold not initialised")
        return self.drift, self.threshold

    @property
    def statistic(self) -> float:
        """Current CUSUM value (the larger side)."""
        return max(self._upper, self._lower)

    def reset(self) -> None:
        self.alarm = False
        self._upper = self._lower = 0.0

    def first_alarm(self, strains: ArrayLike) -> int | None:
        """Index of the first alarming sample of (n, N) ``strains`` (from a reset state), or None.

        Vectorised with S_n = C_n - min(0, min_{j<=n} C_j), C the cumulative sum of increments.
        """
        z = self.score(_series(strains))
        k, h = self._kh
        sides = [z - k] + ([-z - k] if self.two_sided else [])
        first: int | None = None
        for inc in sides:
            hits = np.flatnonzero(cusum(inc) > h)
            if hits.size and (first is None or hits[0] < first):
                first = int(hits[0])
        return first


def cusum(increments: ArrayLike) -> FloatArray:
    """One-sided CUSUM path S_n = max(0, S_{n-1} + x_n), S_0 = 0, for increments x, vectorised."""
    x = np.asarray(increments, dtype=np.float64)
    c = np.cumsum(x)
    return np.asarray(c - np.minimum(np.minimum.accumulate(c), 0.0), dtype=np.float64)
