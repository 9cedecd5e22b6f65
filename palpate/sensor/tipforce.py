"""The tip force grating's wavelength -> the tip's axial load (N), zeroed at rest.

The grating sits on a compliant element between the tip sphere and the beam
(``config.schema.TipGratingConfig``)::

    d_lambda_tip = s_F F + S_T,tip dT

with ``s_F`` the sensitivity (m/N). Its zero is taken at rest with the sensor free, in the pose
of the trial, so the tip sphere's own weight along the axis is part of the zero and the load
read is what the tissue pushes with. With ``temperature_compensation: reference`` the strain-free
reference grating's shift, ``S_T,ref dT``, scaled by ``S_T,tip / S_T,ref``, is taken out first.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..config.schema import FbgConfig, TipGratingConfig

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class TipZero:
    """The tip grating at rest: mean wavelength (m), the standard deviation of a compensated
    reading (m: the reference's noise is in it), the reference grating's mean (m, None without
    one) and how many samples the standard deviation was taken on (the largest zero's)."""

    wavelength: float
    noise: float
    reference: float | None
    samples: int


@dataclass(frozen=True)
class TipForceChain:
    """Tip wavelength -> load (N) with the configured sensitivity and compensation."""

    sensitivity: float  # m/N
    thermal_ratio: float  # S_T,tip / S_T,ref: the reference's shift scaled to the tip grating's
    compensated: bool
    zero: TipZero | None = None

    @classmethod
    def from_config(cls, tip: TipGratingConfig, fbg: FbgConfig) -> TipForceChain:
        ratio = tip.thermal_ratio  # calibrated; else the two coefficients' ratio
        if ratio is None:
            s_ref = fbg.temperature_coefficient
            ratio = tip.temperature_coefficient / s_ref if s_ref > 0 else 0.0
        return cls(tip.sensitivity, ratio, tip.temperature_compensation == "reference")

    def zeroed(self, tip: ArrayLike, reference: ArrayLike | None = None) -> TipForceChain:
        """A copy zeroed on rest samples of the tip grating (n,) (and the reference (n,), which
        the compensated chain needs); ValueError without samples or a needed reference."""
        w = np.asarray(tip, dtype=np.float64).reshape(-1)
        if w.size == 0 or not np.all(np.isfinite(w)):
            raise ValueError("tip grating: no finite samples at rest to zero on")
        ref: float | None = None
        read = w  # what a reading at rest is made of: with compensation, the reference's noise too
        if self.compensated:
            if reference is None:
                raise ValueError("tip grating compensation needs the reference grating's samples")
            r = np.asarray(reference, dtype=np.float64).reshape(-1)
            if r.shape != w.shape:
                raise ValueError(f"reference has {r.size} samples, the tip grating {w.size}")
            ref = float(r.mean())
            read = w - self.thermal_ratio * (r - ref)
        noise, samples = (float(read.std(ddof=1)) if w.size > 1 else 0.0), int(w.size)
        if self.zero is not None and self.zero.samples > samples:
            # a zero taken again on a few frames (the rig's, in a trial) moves the offset, not
            # the noise: 8 frames' standard deviation is below 0.6 sigma one time in twenty,
            # and a contact threshold of 5 of them would trip on the noise
            noise, samples = self.zero.noise, self.zero.samples
        zero = TipZero(float(w.mean()), noise, ref, samples)
        return TipForceChain(self.sensitivity, self.thermal_ratio, self.compensated, zero)

    def force(self, tip: float, reference: float | None = None) -> float:
        """The tip's axial load (N, compression positive) at one sample."""
        z = self._zero()
        shift = tip - z.wavelength
        if self.compensated:
            if reference is None or z.reference is None:
                raise ValueError("tip grating compensation needs the reference grating")
            shift -= self.thermal_ratio * (reference - z.reference)
        return shift / self.sensitivity

    def noise(self) -> float:
        """The load's standard deviation at rest (N), from the zero's samples."""
        return self._zero().noise / self.sensitivity

    def _zero(self) -> TipZero:
        if self.zero is None:
            raise ValueError("tip grating: no zero; call zeroed() on samples at rest first")
        return self.zero


def tip_chain(tip: TipGratingConfig | None, fbg: FbgConfig) -> TipForceChain | None:
    """The chain of a sensor's tip grating (``sensor.tip_grating``), None for a sensor without."""
    return None if tip is None else TipForceChain.from_config(tip, fbg)
