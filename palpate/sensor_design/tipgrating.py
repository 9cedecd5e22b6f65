"""The tip force grating as a design choice: its sensitivity and range against the noise.

A grating on a compliant element at the tip reads the tip's axial load directly
(``config.schema.TipGratingConfig``). The element trades resolution against range: a softer
element shifts the peak more per mN (resolution ``noise / sensitivity``) and reaches the end of
the interrogator's window for that grating sooner (range ``window / sensitivity``), and lets the
stage travel further that is not indentation (its compliance ``L_el / (E A)_el =
sensitivity * L_el / k_eps``, with the bare fiber's strain coefficient ``k_eps`` since the
grating is the element's strain gauge). The choice: the most sensitive of the candidates whose
range still carries ``range_ratio`` times the beam's critical load (the load never exceeds P_cr
by much: the beam buckles), and whose resolution is then reported as a share of P_cr.

The candidates stop at 8 pm/mN: about twice the microsurgical tip sensors' (0.25 mN resolved at
~1 pm of interrogator noise, Iordachita et al. 2009), a sensitivity a printed flexure reaches.
"""

from __future__ import annotations

from dataclasses import dataclass

SENSITIVITIES_PM_PER_MN = (1.0, 2.0, 4.0, 8.0)
WINDOW_PM = 2000.0  # the interrogator's wavelength window for the tip grating's peak
RANGE_RATIO = 2.0  # range / P_cr
ELEMENT_LENGTH = 3e-3  # m, the grating's length on the element
BARE_STRAIN_COEFFICIENT = 1.2  # pm/ue, the grating on the element (not glued on the beam)


@dataclass(frozen=True)
class TipGratingChoice:
    """A tip grating for a sensor: sensitivity (pm/mN), range (mN), element compliance (mm/N),
    resolution (mN, one noise sigma) and that resolution as a share of P_cr."""

    sensitivity_pm_per_mn: float
    range_mn: float
    compliance_mm_per_n: float
    resolution_mn: float
    resolution_share: float

    def as_dict(self) -> dict[str, float]:
        return {
            "sensitivity_pm_per_mn": self.sensitivity_pm_per_mn,
            "range_mn": self.range_mn,
            "compliance_mm_per_n": self.compliance_mm_per_n,
            "resolution_mn": self.resolution_mn,
            "resolution_share": self.resolution_share,
        }


def choose_tip_grating(
    critical_load: float,
    noise_pm: float,
    *,
    sensitivities: tuple[float, ...] = SENSITIVITIES_PM_PER_MN,
    window_pm: float = WINDOW_PM,
    range_ratio: float = RANGE_RATIO,
) -> TipGratingChoice:
    """The tip grating for a beam buckling at ``critical_load`` (N) read with ``noise_pm`` of
    interrogator noise (see the module docstring); ValueError if no candidate's range carries
    ``range_ratio`` P_cr or an input is not positive."""
    if not (critical_load > 0 and noise_pm > 0 and window_pm > 0 and range_ratio > 0):
        raise ValueError("critical_load, noise_pm, window_pm and range_ratio must be > 0")
    p_cr_mn = critical_load * 1e3
    fitting = [s for s in sensitivities if s > 0 and window_pm / s >= range_ratio * p_cr_mn]
    if not fitting:
        raise ValueError(
            f"no tip grating sensitivity in {list(sensitivities)} pm/mN carries "
            f"{range_ratio:g} x P_cr = {range_ratio * p_cr_mn:.3g} mN within {window_pm:g} pm"
        )
    return _choice(max(fitting), noise_pm, window_pm, p_cr_mn)


def tip_grating_for_resolution(
    critical_load: float,
    noise_pm: float,
    resolution: float,
    *,
    window_pm: float = WINDOW_PM,
    range_ratio: float = RANGE_RATIO,
) -> TipGratingChoice:
    """The tip grating that resolves ``resolution`` (N, 1 sigma) at ``noise_pm`` of interrogator
    noise: its sensitivity is ``noise / resolution`` (a published element's resolution, e.g.
    0.25 mN (Iordachita et al. 2009), 0.13 mN (2023), about 0.05 mN (2025), taken as given).
    ValueError if its range does not carry ``range_ratio`` P_cr or an input is not positive.

        >>> round(tip_grating_for_resolution(5e-3, 1.0, 0.05e-3).sensitivity_pm_per_mn, 6)
        20.0
    """
    if not (critical_load > 0 and noise_pm > 0 and resolution > 0 and window_pm > 0):
        raise ValueError("critical_load, noise_pm, resolution and window_pm must be > 0")
    p_cr_mn = critical_load * 1e3
    s = noise_pm / (resolution * 1e3)
    if window_pm / s < range_ratio * p_cr_mn:
        raise ValueError(
            f"a tip grating resolving {resolution * 1e3:.3g} mN ({s:.3g} pm/mN) reaches "
            f"{window_pm / s:.3g} mN, less than {range_ratio:g} x P_cr = "
            f"{range_ratio * p_cr_mn:.3g} mN"
        )
    return _choice(s, noise_pm, window_pm, p_cr_mn)


def _choice(s: float, noise_pm: float, window_pm: float, p_cr_mn: float) -> TipGratingChoice:
    """The grating of sensitivity ``s`` (pm/mN): its range, compliance and resolution."""
    strain_per_mn = s / BARE_STRAIN_COEFFICIENT * 1e-6  # strain on the element per mN
    compliance_mm_per_n = ELEMENT_LENGTH * strain_per_mn * 1e3 * 1e3  # m/mN -> mm/N
    resolution = noise_pm / s
    return TipGratingChoice(s, window_pm / s, compliance_mm_per_n, resolution, resolution / p_cr_mn)
