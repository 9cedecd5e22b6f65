"""Wavelength -> strain (Eq. 1), baseline capture, temperature modes, grating geometry.

Eq. (1): ``d_lambda = k'_eps * eps + S_T * dT``. A grating's peak shift measures the mean strain
over the grating (Eq. 12), so the strain returned per peak *is* the grating-average strain.

Temperature modes (``FbgConfig.temperature_compensation``):

- ``"none"``: the paper's assumption ``dT = 0``;
- ``"measured"``: a measured ``dT`` (K, scalar or per sample) is removed as ``S_T * dT``; for
  offline use only (a dT series from elsewhere): the board's frame protocol carries no
  temperature, so the configuration (``FbgConfig.temperature_compensation``) does not offer it;
- ``"reference"``: a strain-free reference grating's shift is ``S_T,ref * dT``; each peak's
  shift loses it times the grating's own ratio ``S_T,i / S_T,ref`` (``fbg.thermal_ratios``,
  calibrated with ``palpate calibrate --thermal``; 1 each without: then a grating bonded on the
  beam, which reads the beam's expansion too, and S_T's growth with the Bragg wavelength, about
  1 % across 1530-1550 nm, are left in the strain: docs/temperature.md).

All quantities are SI: wavelengths in m, ``k_eps`` in m per unit strain, ``S_T`` in m/K.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..config.schema import FbgConfig

FloatArray = NDArray[np.float64]
TemperatureMode = Literal["none", "measured", "reference"]
MODES: tuple[TemperatureMode, ...] = ("none", "measured", "reference")
PM_PER_UE = 1e-12 / 1e-6
"""1 pm/ue in m per unit strain."""


@dataclass(frozen=True)
class Baseline:
    """Wavelengths at rest (zero strain), from :func:`capture_baseline`.

    ``wavelengths`` (N,) m: mean at rest; ``noise`` (N,) m: standard deviation at rest;
    ``reference`` m or None: mean of the reference grating; ``samples``: how many were averaged.
    """

    wavelengths: FloatArray
    noise: FloatArray
    reference: float | None
    samples: int


def capture_baseline(wavelengths: ArrayLike, reference: ArrayLike | None = None) -> Baseline:
    """Zero the sensor at rest: average ``wavelengths`` of shape (n, N) (and ``reference`` (n,))."""
    w = np.asarray(wavelengths, dtype=np.float64)
    if w.ndim != 2 or w.shape[0] < 1 or w.shape[1] < 1:
        raise ValueError(f"wavelengths must have shape (n >= 1, N >= 1), got {w.shape}")
    if not np.all(np.isfinite(w)):
        raise ValueError("wavelengths at rest contain non-finite values")
    noise = w.std(axis=0, ddof=1) if w.shape[0] > 1 else np.zeros(w.shape[1])
    ref: float | None = None
    if reference is not None:
        r = np.asarray(reference, dtype=np.float64).reshape(-1)
        if r.shape[0] != w.shape[0]:
            raise ValueError(f"reference has {r.shape[0]} samples, wavelengths {w.shape[0]}")
        ref = float(r.mean())
    return Baseline(w.mean(axis=0), noise, ref, int(w.shape[0]))


def wavelength_to_strain(
    wavelengths: ArrayLike,
    baseline: Baseline,
    *,
    k_eps: float,
    mode: TemperatureMode = "none",
    temperature_coefficient: float = 10e-12,
    delta_t: ArrayLike | None = None,
    reference: ArrayLike | None = None,
    ratios: ArrayLike | None = None,
) -> FloatArray:
    """Strain per peak from wavelengths of shape (..., N) (Eq. 1 solved for eps).

    ``delta_t`` (K) has shape () or (...) in mode ``"measured"``; ``reference`` (m) has shape
    (...) in mode ``"reference"``, its shift scaled by each grating's ``ratios`` (N,) (1 each
    when None). Returns shape (..., N), dimensionless.
    """
    if not k_eps > 0:
        raise ValueError(f"k_eps must be > 0, got {k_eps}")
    w = np.asarray(wavelengths, dtype=np.float64)
    if w.shape[-1:] != baseline.wavelengths.shape:
        raise ValueError(
            f"wavelengths end in {w.shape[-1:]}, baseline has {baseline.wavelengths.shape}"
        )
    shift = w - baseline.wavelengths
    if mode == "none":
        thermal: FloatArray | float = 0.0
    elif mode == "measured":
        if delta_t is None:
            raise ValueError("temperature mode 'measured' needs delta_t")
        thermal = temperature_coefficient * np.asarray(delta_t, dtype=np.float64)[..., None]
    elif mode == "reference":
        if reference is None or baseline.reference is None:
            raise ValueError(
                "temperature mode 'reference' needs a reference grating and its baseline"
            )
        thermal = (np.asarray(reference, dtype=np.float64) - baseline.reference)[..., None]
        if ratios is not None:
            thermal = thermal * np.asarray(ratios, dtype=np.float64)
    else:
        raise ValueError(f"unknown temperature mode {mode!r}; expected one of {MODES}")
    return np.asarray((shift - thermal) / k_eps, dtype=np.float64)


@dataclass(frozen=True)
class StrainChain:
    """Eq. (1) with the configured coefficients and temperature mode, plus a captured baseline."""

    k_eps: float
    temperature_coefficient: float
    mode: TemperatureMode
    baseline: Baseline | None = None
    ratios: tuple[float, ...] | None = None  # S_T,i / S_T,ref per peak; None: 1 each

    @classmethod
    def from_config(cls, fbg: FbgConfig, gratings: tuple[int, ...] | None = None) -> StrainChain:
        """The chain of ``fbg`` for the peaks of the gratings numbered ``gratings`` (the
        sensor's ``used_gratings``; their thermal ratios), or 1 each without them."""
        ratios = None
        if gratings is not None and fbg.thermal_ratios is not None:
            ratios = fbg.ratios(gratings)
        return cls(
            fbg.strain_coefficient,
            fbg.temperature_coefficient,
            fbg.temperature_compensation,
            ratios=ratios,
        )

    def zeroed(self, wavelengths: ArrayLike, reference: ArrayLike | None = None) -> StrainChain:
        """A copy zeroed on rest samples (n, N); the reference is required in mode 'reference'."""
        if self.mode == "reference" and reference is None:
            raise ValueError("temperature mode 'reference' needs reference samples to zero on")
        return replace(self, baseline=capture_baseline(wavelengths, reference))

    def strains(
        self,
        wavelengths: ArrayLike,
        *,
        delta_t: ArrayLike | None = None,
        reference: ArrayLike | None = None,
    ) -> FloatArray:
        """Grating-average strains, shape (..., N)."""
        if self.baseline is None:
            raise ValueError("no baseline: call zeroed() on samples at rest first")
        return wavelength_to_strain(
            wavelengths,
            self.baseline,
            k_eps=self.k_eps,
            mode=self.mode,
            temperature_coefficient=self.temperature_coefficient,
            delta_t=delta_t,
            reference=reference,
            ratios=self.ratios,
        )

    def strain_noise(self) -> FloatArray:
        """Per-grating strain noise at rest (N,), from the baseline's wavelength noise."""
        if self.baseline is None:
            raise ValueError("no baseline: call zeroed() on samples at rest first")
        return self.baseline.noise / self.k_eps


def strain_noise(sigma_pm: float, k_pm_per_ue: float = 0.424) -> float:
    """Strain noise (dimensionless) from FBG wavelength noise ``sigma_pm``: sigma / k'_eps."""
    return sigma_pm / k_pm_per_ue * 1e-6
