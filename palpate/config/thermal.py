"""The sensor's temperature in a simulated world (``fidelity.temperature``): an insertion from
the room into the body, and what each grating's thermal shift truly is.

In a body the sensor goes from the room (about 22 degC) to the tissue's temperature (37 degC)
as it is advanced through the endoscope's channel: every grating shifts by about 150 pm (10
pm/degC), 350 ue at 0.424 pm/ue, beside a lung sensor's 15 ue at buckling. The world's
gratings do not share one coefficient: S_T grows with the Bragg wavelength (``lambda (alpha +
xi)``: 1525 to 1560 nm is 2.3 %), and a grating bonded on the beam also reads the beam's
thermal expansion against the fiber's (NiTi's 11 ppm/K against silica's 0.55 ppm/K). The
strain-free reference grating compensates them only with each grating's own ratio
(``fbg.thermal_ratios``, ``sensor.tip_grating.thermal_ratio``: ``palpate calibrate
--thermal``); docs/temperature.md.

Example (a scene's fidelity)::

    fidelity:
      temperature: {step_degc: 15, at_s: 0, time_constant_s: 5, bonded_pm_per_degc: 4}
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .loader import limits


@dataclass(frozen=True)
class TemperatureConfig:
    """The insertion's temperature step and the gratings' true thermal shifts.

    ``step_degc``: the rise from the room to the body; ``at_s``: the virtual time of the
    insertion from the trial's (or the emulator's) start, negative for an insertion before it;
    ``time_constant_s``: the sensor's first-order approach to the tissue's temperature (0: a
    step); ``bonded_pm_per_degc``: the extra shift of the gratings bonded on the beam (its
    expansion against the fiber's; not the reference's or the tip grating's);
    ``wavelength_scaling``: each coefficient grows with its grating's Bragg wavelength (the
    configured coefficients hold at the reference grating's wavelength). The slow drift of a
    procedure stays ``fidelity.temperature_drift_degc_per_s``.
    """

    step_degc: float = field(default=15.0, metadata=limits(ge=-50, le=50))
    at_s: float = field(default=0.0, metadata=limits(ge=-3600, le=3600))
    time_constant_s: float = field(default=5.0, metadata=limits(ge=0, le=600))
    bonded_pm_per_degc: float = field(default=0.0, metadata=limits(ge=-50, le=50))
    wavelength_scaling: bool = True
