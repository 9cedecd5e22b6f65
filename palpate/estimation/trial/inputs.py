"""What a trial's estimator is told besides its record: :class:`EstimatorInputs`.

The same inputs on every path: the simulator builds them from the scene's ``assumed:`` belief
(never from the world's truth), the bench from its trial list and the robot configuration's
calibration; both write them to the log header (``robot.trial.record``) so ``palpate replay``
re-runs the estimate with exactly them. A log from before ``VERSION`` 2 lacks the belief's
ranges, the compliance and the verdict's facts: it replays with its point values (no ranges, a
rigid rig, no verdict limits) and the replay says so (:attr:`EstimatorInputs.version`).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields
from typing import Any

from ...config.loader import from_mapping
from ...config.sample import HALF_SPACE, UNKNOWN, AssumedConfig
from ...config.schema import MM, SensorConfig
from ..beam.section import Section
from ..beam.stage import Stage
from ..belief import Belief
from ..contact.law import ContactLaw

VERSION = 2
DEFAULT_POISSON = 0.45  # the nominal value of an unknown Poisson ratio (the paper's)
Range = tuple[float, float]


@dataclass(frozen=True)
class EstimatorInputs:
    """What the joint fit is told besides the record (all SI).

    Attributes:
        kind: "bench" (exposed length fixed) or "robot" (L = advance - flush translation).
        exposed_length: L on the bench (m); flush_translation: the tube's, on the robot (m).
        tip_radius: the sensor tip's radius (m).
        poisson, thickness, bonded: the belief's nominal values (the paper's estimate uses the
            Poisson ratio; thickness None is a half-space).
        encoder_resolution: stage advance per encoder count (m).
        misalignment: angle between the sensor axis and the surface normal (rad), the IK residual.
        poisson_range: (min, max) when the belief is a range, None for the nominal value.
        thickness_range: (min, max) in m when a range; max None reaches the half-space, min 0
            is ``unknown`` (as thin as the model allows); None for the nominal value.
        bonded_options: (True, False) when the bonding is unknown; None for the nominal value.
        compliance: (min, max) compliance of the tube tip or stage (m/N).
        compliance_calibrated: False when ``compliance`` is the uncalibrated prior range.
        misalignment_tolerance: the campaign's tolerance (rad), None: not checked.
        motion_tolerance: the surface's motion along the axis the campaign tolerates between
            the first touch and the release (m, ``estimation.pose.motion``), None: not checked.
        travel_window: the travel past contact allowed (m), None: unknown.
        orientation_verified: False when probing ran and could not measure a normal (a
            straight tube): the misalignment told is then not known.
        misalignment_sigma: the measured normal's 1-sigma angle (rad), None when no normal was
            measured (no probing, or none found).
        designed_range: the moduli (Pa) the sensor was designed for (None: not stated).
        probe_reason: what probing said when it measured no normal (None: it did, or none ran).
        surface_radius: the convex surface's believed radius (m; the middle of a believed
            range), None: flat or unknown; the contact law takes :attr:`contact_radius`.
        rigid: the sample is a rigid reference: the trial calibrates the rig's compliance
            (``estimation.fits.compliance``) instead of estimating a modulus.
        material: the sample's believed material, ``"linear"`` or ``"neo-hookean"`` (the law
            then carries the finite-strain departure, ``estimation.contact.finite_strain``).
        tip_contact: the believed tip contact, ``"frictionless"`` or ``"sticking"``;
            tip_contact_options: both when the friction is ``unknown``, None otherwise.
        gated: the trial waited for a breath hold (the campaign's gate) and indented in it, so
            an ECG's R waves are taken out as the heart's beat; None (a log that predates it):
            as the rows show, a gated trial's waiting rows.
        version: the inputs' format (VERSION; 1 for logs that predate it).
    """

    kind: str
    exposed_length: float
    flush_translation: float
    tip_radius: float
    poisson: float
    thickness: float | None
    bonded: bool
    encoder_resolution: float
    misalignment: float
    poisson_range: Range | None = None
    thickness_range: tuple[float, float | None] | None = None
    bonded_options: tuple[bool, ...] | None = None
    compliance: Range = (0.0, 0.0)
    compliance_calibrated: bool = True
    misalignment_tolerance: float | None = None
    travel_window: float | None = None
    rigid: bool = False
    orientation_verified: bool = True
    misalignment_sigma: float | None = None
    designed_range: Range | None = None
    probe_reason: str | None = None
    surface_radius: float | None = None
    motion_tolerance: float | None = None
    material: str = "linear"
    tip_contact: str = "frictionless"
    tip_contact_options: tuple[str, ...] | None = None
    gated: bool | None = None
    version: int = VERSION

    @property
    def stage(self) -> Stage:
        """The stage these inputs describe (``palpate.estimation.beam.stage``): the bench's fixed
        exposed length, or a tube's flush translation."""
        return Stage.of(self.kind, self.exposed_length, self.flush_translation)

    @property
    def contact_radius(self) -> float:
        """The contact's effective radius (m): the tip's, or with a convex surface of believed
        radius R_s, Hertz's 1 / (1 / R_tip + 1 / R_s)."""
        if self.surface_radius is None:
            return self.tip_radius
        return 1.0 / (1.0 / self.tip_radius + 1.0 / self.surface_radius)

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> EstimatorInputs:
        """From a log header's ``estimator``; keys a log predates take their defaults (a log
        without ``version`` is version 1), unknown keys raise TypeError."""
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(d) - known)
        if unknown:
            raise TypeError(f"unknown estimator inputs {unknown}")
        values: dict[str, Any] = {k: tuple(v) if isinstance(v, list) else v for k, v in d.items()}
        values.setdefault("version", 1)
        return cls(**values)

    def law(self) -> ContactLaw:
        """The nominal contact law."""
        return ContactLaw(
            self.contact_radius,
            self.poisson,
            self.thickness,
            self.bonded,
            True,
            material=self.material,  # type: ignore[arg-type]
            tip=self.tip_contact,  # type: ignore[arg-type]
        )

    def belief(self) -> Belief:
        """What the joint fit profiles over (``estimation.belief``)."""
        nominal = math.inf if self.thickness is None else self.thickness
        thickness = (nominal, nominal)
        if self.thickness_range is not None:
            lo, hi = self.thickness_range
            thickness = (lo, math.inf if hi is None else hi)
        return Belief(
            self.contact_radius,
            self.poisson_range or (self.poisson, self.poisson),
            thickness,
            self.bonded_options or (self.bonded,),
            self.compliance,
            material=self.material,  # type: ignore[arg-type]
            tips=self.tip_contact_options or (self.tip_contact,),  # type: ignore[arg-type]
        )


def belief_fields(
    assumed: AssumedConfig | None,
    *,
    thickness: float | str | None,
    bonded: bool | str,
    poisson: float,
    surface_radius: float | None = None,
    material: str = "linear",
    tip_contact: str = "frictionless",
) -> dict[str, Any]:
    """The :class:`EstimatorInputs` fields of an operator's belief (``poisson``, ``thickness``,
    ``bonded`` and their ranges): each key of ``assumed`` (``config.sample.AssumedConfig``)
    that is left out takes the default given here, in the same forms: ``thickness`` in m (None
    or ``"half-space"``: a half-space; ``"unknown"``), ``bonded`` (or ``"unknown"``),
    ``poisson``, ``surface_radius`` (m, None: flat), ``material``, ``tip_contact``
    (``frictionless`` or ``sticking``). A scene gives the sample's own values; the bench gives
    thickness and bonding ``"unknown"``, the trial's Poisson ratio, no radius, a linear material
    and a frictionless tip (the paper's law)."""
    a = assumed or AssumedConfig()
    h = thickness if a.thickness_mm is None else _thickness_m(a.thickness_mm)
    b = bonded if a.bonded is None else a.bonded
    nu = poisson if a.poisson is None else a.poisson
    out: dict[str, Any] = {}
    if isinstance(h, tuple):
        out["thickness_range"] = h
        out["thickness"] = _middle_thickness(h)
    elif h == UNKNOWN:
        out["thickness_range"] = (0.0, None)
        out["thickness"] = None
    elif h is None or h == HALF_SPACE:
        out["thickness"] = None
    elif isinstance(h, int | float):
        out["thickness"] = float(h)
    else:
        raise ValueError(f"thickness: expected a value, a range or 'unknown', got {h!r}")
    if b == UNKNOWN:
        out["bonded_options"] = (True, False)
        out["bonded"] = True
    else:
        out["bonded"] = bool(b)
    if nu == UNKNOWN:
        out["poisson_range"] = (0.0, 0.5)
        out["poisson"] = DEFAULT_POISSON
    elif isinstance(nu, tuple):
        out["poisson_range"] = (float(nu[0]), float(nu[1]))
        out["poisson"] = 0.5 * (nu[0] + nu[1])
    elif isinstance(nu, int | float):
        out["poisson"] = float(nu)
    else:
        raise ValueError(f"poisson: expected a value, a range or 'unknown', got {nu!r}")
    radii = a.surface_radius(surface_radius)
    if radii is not None:
        out["surface_radius"] = 0.5 * (radii[0] + radii[1])
    return out | _material_fields(a, material, tip_contact)


def _material_fields(a: AssumedConfig, material: str, tip_contact: str) -> dict[str, Any]:
    """The material and tip-contact fields of ``a`` (a left-out key takes the given default)."""
    out: dict[str, Any] = {"material": material if a.material is None else a.material}
    friction = tip_contact if a.friction is None else a.friction
    if friction == UNKNOWN:
        out["tip_contact_options"] = ("frictionless", "sticking")
        out["tip_contact"] = "frictionless"
    else:
        out["tip_contact"] = friction
    return out


def _thickness_m(value: object) -> object:
    """An ``assumed.thickness_mm`` value in m (strings pass through)."""
    if isinstance(value, tuple):
        return (value[0] * MM, value[1] * MM)
    if isinstance(value, int | float):
        return value * MM
    return value


def _middle_thickness(r: tuple[float, float]) -> float:
    """The thickness in the middle of a range in 1/h (the thin-layer series' variable)."""
    return 2.0 / (1.0 / r[0] + 1.0 / r[1])


def probe_inputs(probe: dict[str, Any]) -> dict[str, Any]:
    """The :class:`EstimatorInputs` fields a log's ``probe`` record sets: the misalignment
    probing measured, whether a normal was measured at all and its 1-sigma angle (rad)."""
    raw = probe.get("normal_sigma")
    measured = probe.get("normal") is not None
    sigma = float(raw) if isinstance(raw, int | float) else math.nan
    reason = probe.get("reason")
    return {
        "misalignment": probe["misalignment"],
        "probe_reason": None if measured or not isinstance(reason, str) else reason,
        "orientation_verified": measured,
        "misalignment_sigma": sigma if measured and math.isfinite(sigma) else None,
    }


def header_sensor(
    header: dict[str, Any], source: str = "<log>"
) -> tuple[SensorConfig, Section, EstimatorInputs]:
    """The sensor, its section and the estimator's inputs a log header records (what the
    record's strains are read with). Raises ``ConfigError``/``KeyError`` where it lacks them."""
    raw = {k: tuple(v) if isinstance(v, list) else v for k, v in header["sensor"].items()}
    sensor = from_mapping(SensorConfig, raw, source, "sensor")
    section = Section(**{f.name: header["section"][f.name] for f in fields(Section)})
    return sensor, section, EstimatorInputs.from_dict(header["estimator"])
