"""The optics of the sensor's gratings: Eq. (1)'s coefficients and the gratings' Bragg
wavelengths (:class:`FbgConfig`), and the optional tip force grating (:class:`TipGratingConfig`).
Re-exported by :mod:`config.schema`, where the rest of the robot's configuration lives."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

from .loader import limits

MM = 1e-3
UE = 1e-6
PM = 1e-12
NM = 1e-9


@dataclass(frozen=True)
class TipGratingConfig:
    """An optional force grating at the sensor's tip (``sensor.tip_grating``): a grating on a
    compliant element between the tip sphere and the beam that sees the tip's axial load.

    ``sensitivity_pm_per_mn``: its peak shift per mN of load; ``range_mn``: the load the element
    carries before it bottoms out (the designed range); ``compliance_mm_per_n``: the element's
    axial compliance, stage travel that is not indentation; ``temperature_coefficient_pm_per_degc``:
    its thermal shift, compensated with the strain-free reference grating
    (``fbg.reference_wavelength_nm``, sent by the board: ``board.has_reference``) when
    ``temperature_compensation`` is ``reference``; ``thermal_ratio``: its thermal shift per the
    reference's, as calibrated (``palpate calibrate --thermal``; null: the two coefficients'
    ratio); ``base_wavelength_nm``: its Bragg wavelength at rest. The board sends its peak in
    every frame (frame protocol revision 1.1).
    """

    sensitivity_pm_per_mn: float = field(default=10.0, metadata=limits(gt=0, le=1000))
    range_mn: float = field(default=50.0, metadata=limits(gt=0, le=100000))
    compliance_mm_per_n: float = field(default=0.03, metadata=limits(ge=0, le=100))
    temperature_coefficient_pm_per_degc: float = field(default=10.0, metadata=limits(ge=0, le=100))
    temperature_compensation: Literal["none", "reference"] = "reference"
    thermal_ratio: float | None = field(default=None, metadata=limits(gt=0, le=10))
    base_wavelength_nm: float = field(default=1560.0, metadata=limits(gt=0, le=4000))

    @property
    def sensitivity(self) -> float:
        """m of wavelength per N of tip load."""
        return self.sensitivity_pm_per_mn * PM / 1e-3

    @property
    def range(self) -> float:
        """The element's load range, N."""
        return self.range_mn * 1e-3

    @property
    def compliance(self) -> float:
        """The element's axial compliance, m/N."""
        return self.compliance_mm_per_n * MM

    @property
    def temperature_coefficient(self) -> float:
        """m of wavelength per kelvin."""
        return self.temperature_coefficient_pm_per_degc * PM

    @property
    def base_wavelength(self) -> float:
        return self.base_wavelength_nm * NM


@dataclass(frozen=True)
class FbgConfig:
    """Optics of the FBG fiber: Eq. (1) coefficients and the gratings' Bragg wavelengths."""

    strain_coefficient_pm_per_ue: float = field(default=0.424, metadata=limits(gt=0, le=10))
    bare_strain_coefficient_pm_per_ue: float = field(default=1.2, metadata=limits(gt=0, le=10))
    temperature_coefficient_pm_per_degc: float = field(default=10.0, metadata=limits(ge=0, le=100))
    # "measured" (a separately measured dT) is not offered: the board's frame protocol carries
    # no temperature, so nothing could supply it (sensor.strain keeps it for offline use)
    temperature_compensation: Literal["none", "reference"] = "none"
    base_wavelengths_nm: tuple[float, ...] = (1530.0, 1535.0, 1540.0, 1545.0, 1550.0)
    reference_wavelength_nm: float | None = None
    # Each grating's thermal shift per the reference grating's (S_T,i / S_T,ref), one per
    # base_wavelengths_nm, as calibrated on a record through a temperature change (`palpate
    # calibrate --thermal`): gratings bonded on the beam see its expansion too, and S_T grows
    # with the Bragg wavelength. null: 1 each (the same S_T for every grating).
    thermal_ratios: tuple[float, ...] | None = None
    strain_limit_ue: float = field(default=5000.0, metadata=limits(gt=0, le=20000))

    def validate(self) -> None:
        if self.temperature_compensation == "reference" and self.reference_wavelength_nm is None:
            raise ValueError(
                "temperature_compensation 'reference' needs reference_wavelength_nm "
                "(a strain-free grating)"
            )
        ratios = self.thermal_ratios
        if ratios is not None:
            if len(ratios) != len(self.base_wavelengths_nm):
                raise ValueError(
                    f"thermal_ratios: one per base_wavelengths_nm ({len(self.base_wavelengths_nm)}"
                    f"), got {len(ratios)}"
                )
            if not all(0 < r <= 10 for r in ratios):
                raise ValueError(f"thermal_ratios: each in (0, 10], got {list(ratios)}")

    def ratios(self, gratings: tuple[int, ...]) -> tuple[float, ...]:
        """The thermal ratios of the gratings numbered ``gratings`` (1-based), 1 without any."""
        if self.thermal_ratios is None:
            return tuple(1.0 for _ in gratings)
        return tuple(self.thermal_ratios[g - 1] for g in gratings)

    @property
    def strain_coefficient(self) -> float:
        """k'_eps in m of wavelength per unit strain."""
        return self.strain_coefficient_pm_per_ue * PM / UE

    @property
    def temperature_coefficient(self) -> float:
        """S_T in m of wavelength per kelvin."""
        return self.temperature_coefficient_pm_per_degc * PM

    @property
    def strain_limit(self) -> float:
        return self.strain_limit_ue * UE
