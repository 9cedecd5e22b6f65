"""What the interrogator reads off the gratings: each peak's wavelength from the fiber's strain
and the temperature drift, the strain-free reference grating, and the interrogator's noise.

Plain floats, with the same IEEE operations in the same order as the array expressions they
replaced, so the same bits (``sim.world.World.sample`` calls it at every board sample).
"""

from __future__ import annotations

import numpy as np

from config.scene import FidelityConfig
from config.schema import FbgConfig, SensorConfig


class GratingReadout:
    """The peaks of the used gratings and the reference grating, as the board would send them."""

    def __init__(self, sensor: SensorConfig, fbg: FbgConfig, fidelity: FidelityConfig) -> None:
        self._base = tuple(fbg.base_wavelengths_nm[g - 1] * 1e-9 for g in sensor.used_gratings)
        self._noise = fidelity.fbg_noise_pm * 1e-12
        ref_nm = fbg.reference_wavelength_nm
        self._reference = None if ref_nm is None else ref_nm * 1e-9
        # peak noises, then the reference's, drawn in one call (the same stream as separate ones)
        self._draws = (len(self._base) + (ref_nm is not None)) if self._noise > 0 else 0
        self._strain_coefficient = fbg.strain_coefficient
        self._temperature_coefficient = fbg.temperature_coefficient

    def read(
        self, strains: tuple[float, ...], drift: float, rng: np.random.Generator
    ) -> tuple[tuple[float, ...], float | None]:
        """Peak wavelengths (m) and the reference's (m, None without one) at fiber strains
        ``strains`` and a temperature change ``drift`` (deg C); the noise is drawn from ``rng``."""
        noise = rng.normal(0.0, self._noise, size=self._draws).tolist() if self._draws else []
        reference = None
        if self._reference is not None:
            reference = self._reference
            reference += self._temperature_coefficient * drift
            if noise:
                reference += noise[-1]
        return self._peaks(strains, drift, noise), reference

    def _peaks(
        self, strains: tuple[float, ...], drift: float, noise: list[float]
    ) -> tuple[float, ...]:
        """Peak wavelengths (m): base + S_eps eps (+ S_T dT) (+ noise)."""
        k = self._strain_coefficient
        shift = [k * x for x in strains]
        if drift:
            offset = self._temperature_coefficient * drift
            shift = [x + offset for x in shift]
        wl = [b + x for b, x in zip(self._base, shift, strict=True)]
        if noise:
            wl = [w + n for w, n in zip(wl, noise[: len(wl)], strict=True)]
        return tuple(wl)
