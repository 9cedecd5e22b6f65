"""What the interrogator reads off the gratings: each peak's wavelength from the fiber's strain
and the temperature (each grating's own thermal shift, sim/thermal.py), the strain-free
reference grating, the tip force grating, and the interrogator's noise.

Plain floats, with the same IEEE operations in the same order as the array expressions they
replaced, so the same bits (``sim.world.World.sample`` calls it at every board sample).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..config.scene import FidelityConfig
from ..config.schema import FbgConfig, SensorConfig, TipGratingConfig
from .thermal import ThermalCoefficients, ThermalHistory, true_coefficients


class BoardReadout:
    """Every peak the board sends at one instant: the gratings', the reference's and the tip
    grating's, at the world's temperature then (:class:`sim.thermal.ThermalHistory`)."""

    def __init__(self, sensor: SensorConfig, fbg: FbgConfig, fidelity: FidelityConfig) -> None:
        self.history = ThermalHistory.of(fidelity)
        thermal = true_coefficients(sensor, fbg, fidelity)
        self.gratings = GratingReadout(sensor, fbg, fidelity, thermal)
        tip = sensor.tip_grating
        self.tip = None if tip is None else TipReadout(tip, fidelity, thermal.tip)

    def read(
        self, strains: tuple[float, ...], load: float, t: float, rng: np.random.Generator
    ) -> tuple[tuple[float, ...], float | None, float | None]:
        """The peaks (m), the reference's and the tip grating's (m, None without one) at fiber
        strains ``strains``, an axial tip load ``load`` (N) and virtual time ``t`` (s)."""
        drift = self.history.change(t)
        wavelengths, reference = self.gratings.read(strains, drift, rng)
        tip = None if self.tip is None else self.tip.read(load, drift, rng)
        return wavelengths, reference, tip


class GratingReadout:
    """The peaks of the used gratings and the reference grating, as the board would send them."""

    def __init__(
        self,
        sensor: SensorConfig,
        fbg: FbgConfig,
        fidelity: FidelityConfig,
        thermal: ThermalCoefficients,
    ) -> None:
        """``thermal``: the gratings' true shifts per kelvin (``sim.thermal.true_coefficients``)."""
        self._base = tuple(fbg.base_wavelengths_nm[g - 1] * 1e-9 for g in sensor.used_gratings)
        self._noise = fidelity.fbg_noise
        ref_nm = fbg.reference_wavelength_nm
        self._reference = None if ref_nm is None else ref_nm * 1e-9
        # peak noises, then the reference's, drawn in one call (the same stream as separate ones)
        self._draws = (len(self._base) + (ref_nm is not None)) if self._noise > 0 else 0
        self._strain_coefficient = fbg.strain_coefficient
        self._thermal = thermal.gratings
        self._reference_thermal = thermal.reference

    def read(
        self, strains: tuple[float, ...], drift: float, rng: np.random.Generator
    ) -> tuple[tuple[float, ...], float | None]:
        """Peak wavelengths (m) and the reference's (m, None without one) at fiber strains
        ``strains`` and a temperature change ``drift`` (deg C); the noise is drawn from ``rng``."""
        noise = rng.normal(0.0, self._noise, size=self._draws).tolist() if self._draws else []
        reference = None
        if self._reference is not None:
            reference = self._reference
            reference += self._reference_thermal * drift
            if noise:
                reference += noise[-1]
        return self._peaks(strains, drift, noise), reference

    def _peaks(
        self, strains: tuple[float, ...], drift: float, noise: list[float]
    ) -> tuple[float, ...]:
        """Peak wavelengths (m): base + S_eps eps (+ S_T,i dT) (+ noise)."""
        k = self._strain_coefficient
        shift = [k * x for x in strains]
        if drift:
            shift = [x + c * drift for x, c in zip(shift, self._thermal, strict=True)]
        wl = [b + x for b, x in zip(self._base, shift, strict=True)]
        if noise:
            wl = [w + n for w, n in zip(wl, noise[: len(wl)], strict=True)]
        return tuple(wl)


class TipReadout:
    """The tip force grating's peak: its Bragg wavelength plus the sensitivity times the tip's
    axial load (clipped at the element's range: past it the element has bottomed out and the
    grating reads no more), its own thermal shift, and the interrogator's noise."""

    def __init__(
        self, tip: TipGratingConfig, fidelity: FidelityConfig, thermal: float | None = None
    ) -> None:
        """``thermal``: its true shift per kelvin (m/K; default: the configured one)."""
        self._base = tip.base_wavelength
        self._sensitivity = tip.sensitivity
        self._range = tip.range
        self._thermal = tip.temperature_coefficient if thermal is None else thermal
        self._noise = fidelity.fbg_noise

    def read(self, load: float, drift: float, rng: np.random.Generator) -> float:
        """The peak (m) at an axial tip load ``load`` (N) and a temperature change ``drift``
        (deg C); the noise is drawn from ``rng`` after the gratings' own."""
        wl = self._base + self._sensitivity * min(load, self._range) + self._thermal * drift
        if self._noise > 0:
            wl += float(rng.normal(0.0, self._noise))
        return wl


def grating_ends(centres: tuple[float, ...], grating_length: float) -> NDArray[np.float64]:
    """(n, 2) distances from the tip (m) of each grating's two ends."""
    half = 0.5 * grating_length
    ends: NDArray[np.float64] = np.asarray(centres)[:, None] + np.array([-half, half])
    return ends
