"""The sensor's temperature in the world: its change at a virtual time, and each grating's true
thermal shift per degree (``fidelity.temperature``, config/thermal.py).

Without ``fidelity.temperature`` the change is the drift alone (``temperature_drift_degc_per_s``
times the time) and every grating shifts by the configured ``fbg.temperature_coefficient`` (the
tip grating by its own), the world of every scene before it.

Usage::

    history = ThermalHistory.of(fidelity)
    history.change(12.0)  # deg C since the world's start
    coefficients = true_coefficients(sensor, fbg, fidelity)  # m/K per used grating, ref, tip
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..config.scene import FidelityConfig
from ..config.schema import FbgConfig, SensorConfig
from ..config.thermal import TemperatureConfig


@dataclass(frozen=True)
class ThermalHistory:
    """The temperature change (deg C) at a virtual time: the drift, plus the insertion's step
    approached with its time constant once it has begun."""

    drift: float  # deg C/s
    insertion: TemperatureConfig | None = None

    @classmethod
    def of(cls, fidelity: FidelityConfig) -> ThermalHistory:
        return cls(fidelity.temperature_drift_degc_per_s, fidelity.temperature)

    def change(self, t: float) -> float:
        """deg C at virtual time ``t`` (s) against the world's start."""
        d = self.drift * t
        step = self.insertion
        if step is None:
            return d
        age = t - step.at_s
        if age <= 0:
            return d
        if step.time_constant_s <= 0:
            return d + step.step_degc
        return d + step.step_degc * -math.expm1(-age / step.time_constant_s)


@dataclass(frozen=True)
class ThermalCoefficients:
    """The world's true thermal shifts (m/K): each used grating's, the reference's, the tip's."""

    gratings: tuple[float, ...]
    reference: float
    tip: float | None


def true_coefficients(
    sensor: SensorConfig, fbg: FbgConfig, fidelity: FidelityConfig
) -> ThermalCoefficients:
    """What each grating truly shifts per kelvin in a world with ``fidelity`` (see the module
    docstring): the configured coefficients, each scaled by its Bragg wavelength against the
    reference's and, on the beam, plus the bonded gratings' extra shift."""
    s_t = fbg.temperature_coefficient
    tip = sensor.tip_grating
    tip_s = None if tip is None else tip.temperature_coefficient
    step = fidelity.temperature
    if step is None:
        return ThermalCoefficients(tuple(s_t for _ in sensor.used_gratings), s_t, tip_s)
    base = [fbg.base_wavelengths_nm[g - 1] for g in sensor.used_gratings]
    at = fbg.reference_wavelength_nm or sum(base) / len(base)
    scale = (lambda nm: nm / at) if step.wavelength_scaling else (lambda nm: 1.0)
    bonded = step.bonded_pm_per_degc * 1e-12
    gratings = tuple(s_t * scale(nm) + bonded for nm in base)
    reference = s_t * scale(at)
    if tip is not None and tip_s is not None:
        tip_s = tip_s * scale(tip.base_wavelength_nm)
    return ThermalCoefficients(gratings, reference, tip_s)
