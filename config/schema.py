"""Typed configuration: the YAML keys, their units, defaults from the paper, and ranges.

Field names are the YAML keys, so a non-SI key says its unit (``fiber_radius_mm``); the SI value is
a property without the suffix (``fiber_radius`` in m). Defaults are the paper's sensor and robot
(Moradkhani et al., "An FBG-based Stiffness Estimation Sensor for In-vivo Diagnostics").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

from config.loader import limits

MM = 1e-3
GPA = 1e9
UE = 1e-6
PM = 1e-12
NM = 1e-9

# Control ticks per second when a scene or a bench file does not say (``control_rate_hz``): one
# default for the simulator and the bench, the rate the shipped files use.
DEFAULT_CONTROL_RATE_HZ = 250.0


@dataclass(frozen=True)
class SensorConfig:
    """The composite beam: one FBG fiber glued on a row of NiTi wires, with a spherical tip."""

    fiber_radius_mm: float = field(default=0.115, metadata=limits(gt=0, le=1))
    fiber_modulus_gpa: float = field(default=67.0, metadata=limits(gt=0, le=1000))
    wire_radius_mm: float = field(default=0.1, metadata=limits(gt=0, le=1))
    wire_count: int = field(default=4, metadata=limits(ge=0, le=32))
    wire_modulus_gpa: float = field(default=55.0, metadata=limits(gt=0, le=1000))
    tip_radius_mm: float = field(default=3.5, metadata=limits(gt=0, le=50))
    exposed_length_mm: float = field(default=42.0, metadata=limits(gt=0, le=500))
    grating_count: int = field(default=5, metadata=limits(ge=1, le=32))
    grating_spacing_mm: float = field(default=8.0, metadata=limits(gt=0, le=100))
    grating_length_mm: float = field(default=3.0, metadata=limits(gt=0, le=50))
    first_grating_from_tip_mm: float = field(default=10.0, metadata=limits(ge=0, le=500))
    used_gratings: tuple[int, ...] = (1, 2, 3)
    # Weight (for scenes that model gravity): the printed tip sphere (3.5 mm, ~1.18 g/cm^3
    # MJP resin) and the beam (four NiTi wires, 6.45 g/cm^3, and the fiber).
    tip_mass_g: float = field(default=0.21, metadata=limits(ge=0, le=100))
    linear_mass_g_per_m: float = field(default=0.9, metadata=limits(ge=0, le=1000))

    def validate(self) -> None:
        if not self.used_gratings:
            raise ValueError("used_gratings: at least one grating must be used")
        for g in self.used_gratings:
            if not 1 <= g <= self.grating_count:
                raise ValueError(f"used_gratings: grating {g} is not in 1..{self.grating_count}")
        if len(set(self.used_gratings)) != len(self.used_gratings):
            raise ValueError("used_gratings: a grating is listed twice")

    @property
    def fiber_radius(self) -> float:
        return self.fiber_radius_mm * MM

    @property
    def fiber_modulus(self) -> float:
        return self.fiber_modulus_gpa * GPA

    @property
    def wire_radius(self) -> float:
        return self.wire_radius_mm * MM

    @property
    def wire_modulus(self) -> float:
        return self.wire_modulus_gpa * GPA

    @property
    def tip_radius(self) -> float:
        return self.tip_radius_mm * MM

    @property
    def exposed_length(self) -> float:
        return self.exposed_length_mm * MM

    @property
    def tip_mass(self) -> float:
        return self.tip_mass_g * 1e-3

    @property
    def linear_mass(self) -> float:
        return self.linear_mass_g_per_m * 1e-3

    @property
    def grating_length(self) -> float:
        return self.grating_length_mm * MM

    def grating_centres_from_tip(self) -> tuple[float, ...]:
        """Distances (m) from the sensor tip to the centre of each used grating."""
        return tuple(
            (self.first_grating_from_tip_mm + (g - 1) * self.grating_spacing_mm) * MM
            for g in self.used_gratings
        )


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
    strain_limit_ue: float = field(default=5000.0, metadata=limits(gt=0, le=20000))

    def validate(self) -> None:
        if self.temperature_compensation == "reference" and self.reference_wavelength_nm is None:
            raise ValueError(
                "temperature_compensation 'reference' needs reference_wavelength_nm "
                "(a strain-free grating)"
            )

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


@dataclass(frozen=True)
class BoardConfig:
    """The acquisition board's serial stream (frame format in docs/frame-protocol.md)."""

    port: str = "sim"
    baudrate: int = field(default=921600, metadata=limits(gt=0))
    rate_hz: float = field(default=1000.0, metadata=limits(gt=0, le=100000))
    stale_timeout_s: float = field(default=0.1, metadata=limits(gt=0, le=60))
    has_reference: bool = False
    has_force: bool = False


@dataclass(frozen=True)
class ServoConfig:
    """One Dynamixel servo: its bus ID and model (checked against the model number on connect)."""

    id: int = field(default=1, metadata=limits(ge=0, le=252))
    model: Literal["XM430-W350", "XL430-W250"] = "XM430-W350"


@dataclass(frozen=True)
class ServoBusConfig:
    """The Dynamixel bus: port, baud rate, and the three servos of the roller-gear drive.

    ``timeout_ms`` is how long the driver waits for a status packet beyond its transmission time;
    a transaction that fails on the wire is retried ``retries`` times. ``max_goal_step_deg`` is
    the safety clamp on how far a servo's goal may move in one control tick (shaft degrees).
    """

    port: str = "sim"
    baudrate: int = field(default=1000000, metadata=limits(gt=0))
    timeout_ms: float = field(default=20.0, metadata=limits(gt=0, le=10000))
    retries: int = field(default=3, metadata=limits(ge=0, le=20))
    max_goal_step_deg: float = field(default=10.0, metadata=limits(gt=0, le=360))
    outer_roll: ServoConfig = ServoConfig(id=1)
    inner_roll: ServoConfig = ServoConfig(id=2)
    translation: ServoConfig = ServoConfig(id=3, model="XL430-W250")

    def validate(self) -> None:
        ids = [self.outer_roll.id, self.inner_roll.id, self.translation.id]
        if len(set(ids)) != len(ids):
            raise ValueError(f"servo ids must differ, got {ids}")

    @property
    def timeout(self) -> float:
        return self.timeout_ms * 1e-3

    @property
    def max_goal_step(self) -> float:
        """Largest change of a servo goal per control tick, rad of servo shaft."""
        return math.radians(self.max_goal_step_deg)


@dataclass(frozen=True)
class DriveConfig:
    """Dual roller-gear drive: joint space (roll phi, stage translation) <-> servo shaft angles.

    Servo shaft angles: outer = outer_roll_ratio * phi, inner = inner_roll_ratio * phi (the inner
    roll is slaved to the outer one so the sensor does not twist), translation servo =
    2 pi / lead * (translation - coupling * phi). ``coupling_mm_per_rad`` is the translation a
    roll produces by itself (0 for an ideal roller gear). ``home_*`` is the pose the drive is in
    when it is homed (software homing: present shaft angles are taken as this pose).
    """

    outer_roll_ratio: float = field(default=1.0, metadata=limits(gt=0, le=1000))
    inner_roll_ratio: float = field(default=1.0, metadata=limits(gt=0, le=1000))
    lead_mm_per_rev: float = field(default=20.0, metadata=limits(gt=0, le=1000))
    coupling_mm_per_rad: float = field(default=0.0, metadata=limits(ge=-100, le=100))
    translation_min_mm: float = field(default=0.0, metadata=limits(ge=-1000, le=1000))
    translation_max_mm: float = field(default=80.0, metadata=limits(ge=-1000, le=1000))
    roll_min_deg: float = field(default=-200.0, metadata=limits(ge=-3600, le=3600))
    roll_max_deg: float = field(default=200.0, metadata=limits(ge=-3600, le=3600))
    max_speed_mm_per_s: float = field(default=5.0, metadata=limits(gt=0, le=1000))
    max_roll_speed_deg_per_s: float = field(default=90.0, metadata=limits(gt=0, le=10000))
    max_accel_mm_per_s2: float = field(default=50.0, metadata=limits(gt=0, le=100000))
    max_roll_accel_deg_per_s2: float = field(default=360.0, metadata=limits(gt=0, le=1000000))
    home_translation_mm: float = field(default=0.0, metadata=limits(ge=-1000, le=1000))
    home_roll_deg: float = field(default=0.0, metadata=limits(ge=-3600, le=3600))
    # The inner roller gear is slaved to the outer one; a twist between them beyond this (a
    # slipping gear, a stalled servo) stops the trial and retracts.
    max_twist_deg: float = field(default=3.0, metadata=limits(gt=0, le=360))

    def validate(self) -> None:
        if self.translation_min_mm >= self.translation_max_mm:
            raise ValueError("translation_min_mm must be below translation_max_mm")
        if self.roll_min_deg >= self.roll_max_deg:
            raise ValueError("roll_min_deg must be below roll_max_deg")
        if not self.translation_min_mm <= self.home_translation_mm <= self.translation_max_mm:
            raise ValueError("home_translation_mm must lie within the translation limits")
        if not self.roll_min_deg <= self.home_roll_deg <= self.roll_max_deg:
            raise ValueError("home_roll_deg must lie within the roll limits")

    @property
    def lead(self) -> float:
        """Translation of the inner roller gear per servo revolution, in m."""
        return self.lead_mm_per_rev * MM

    @property
    def coupling(self) -> float:
        """Translation per rad of roll, m/rad."""
        return self.coupling_mm_per_rad * MM

    @property
    def translation_limits(self) -> tuple[float, float]:
        return self.translation_min_mm * MM, self.translation_max_mm * MM

    @property
    def roll_limits(self) -> tuple[float, float]:
        return math.radians(self.roll_min_deg), math.radians(self.roll_max_deg)

    @property
    def max_speed(self) -> float:
        return self.max_speed_mm_per_s * MM

    @property
    def max_twist(self) -> float:
        return math.radians(self.max_twist_deg)

    @property
    def max_roll_speed(self) -> float:
        return math.radians(self.max_roll_speed_deg_per_s)

    @property
    def max_accel(self) -> float:
        return self.max_accel_mm_per_s2 * MM

    @property
    def max_roll_accel(self) -> float:
        return math.radians(self.max_roll_accel_deg_per_s2)

    @property
    def home_translation(self) -> float:
        return self.home_translation_mm * MM

    @property
    def home_roll(self) -> float:
        return math.radians(self.home_roll_deg)


@dataclass(frozen=True)
class TubeConfig:
    """A 3D-printed tube: straight part, then a constant-curvature arc turning by tip_angle_deg.

    ``flush_translation_mm`` is the stage translation at which the centre of the sensor's tip
    sphere is at the tube tip (exposed length L = 0); L = translation - flush translation.

    ``compliance_mm_per_n``: the tube tip's axial compliance (mm of tip travel per N of load),
    calibrated on a rigid reference (``palpate calibrate``): a value or the calibration's
    ``[min, max]``; null = not calibrated (the estimate then spans
    ``calibration.uncalibrated_compliance_max_mm_per_n`` and says so).
    """

    name: str
    tip_angle_deg: float = field(default=0.0, metadata=limits(ge=0, le=180))
    straight_length_mm: float = field(default=40.0, metadata=limits(ge=0, le=1000))
    arc_length_mm: float = field(default=40.0, metadata=limits(ge=0, le=1000))
    flush_translation_mm: float = field(default=0.0, metadata=limits(ge=-1000, le=1000))
    compliance_mm_per_n: float | tuple[float, float] | None = field(
        default=None, metadata=limits(ge=0, le=100)
    )

    def validate(self) -> None:
        if self.tip_angle_deg > 0 and self.arc_length_mm <= 0:
            raise ValueError(f"tube {self.name!r}: a bent tube needs arc_length_mm > 0")
        check_compliance("compliance_mm_per_n", self.compliance_mm_per_n)

    @property
    def tip_angle(self) -> float:
        return math.radians(self.tip_angle_deg)

    @property
    def straight_length(self) -> float:
        return self.straight_length_mm * MM

    @property
    def arc_length(self) -> float:
        return self.arc_length_mm * MM

    @property
    def flush_translation(self) -> float:
        return self.flush_translation_mm * MM


def check_compliance(key: str, value: float | tuple[float, float] | None) -> None:
    """ValueError naming ``key`` unless a [min, max] compliance has min <= max."""
    if isinstance(value, tuple) and not value[0] <= value[1]:
        raise ValueError(f"{key}: a range [min, max] needs min <= max, got {list(value)}")


def compliance_range(value: float | tuple[float, float] | None) -> tuple[float, float] | None:
    """A compliance key as (min, max) in m/N; None when not calibrated."""
    if value is None:
        return None
    lo, hi = value if isinstance(value, tuple) else (value, value)
    return lo * MM, hi * MM


@dataclass(frozen=True)
class CalibrationConfig:
    """What is calibrated besides the tubes: the bench-top stage's compliance (as a tube's
    ``compliance_mm_per_n``; null = not calibrated) and the range an uncalibrated compliance is
    taken to span, ``[0, uncalibrated_compliance_max_mm_per_n]`` (0.1 mm/N: a tip as compliant
    as 10 N/mm, the printed tube the paper blames for its robot errors)."""

    stage_compliance_mm_per_n: float | tuple[float, float] | None = field(
        default=None, metadata=limits(ge=0, le=100)
    )
    uncalibrated_compliance_max_mm_per_n: float = field(default=0.1, metadata=limits(gt=0, le=100))

    def validate(self) -> None:
        check_compliance("stage_compliance_mm_per_n", self.stage_compliance_mm_per_n)


DEFAULT_TUBES: tuple[TubeConfig, ...] = (
    TubeConfig(name="straight", tip_angle_deg=0.0),
    TubeConfig(name="bent15", tip_angle_deg=15.0),
    TubeConfig(name="bent30", tip_angle_deg=30.0),
    TubeConfig(name="bent50", tip_angle_deg=50.0),
)


@dataclass(frozen=True)
class StackConfig:
    """Everything the control stack needs to run one robot: ``config/robot.yaml``."""

    sensor: SensorConfig = SensorConfig()
    fbg: FbgConfig = FbgConfig()
    board: BoardConfig = BoardConfig()
    servos: ServoBusConfig = ServoBusConfig()
    drive: DriveConfig = DriveConfig()
    tubes: tuple[TubeConfig, ...] = DEFAULT_TUBES
    calibration: CalibrationConfig = CalibrationConfig()

    def validate(self) -> None:
        names = [t.name for t in self.tubes]
        if len(set(names)) != len(names):
            raise ValueError(f"tubes: names must be unique, got {names}")
        if len(self.fbg.base_wavelengths_nm) < self.sensor.grating_count:
            raise ValueError(
                f"fbg.base_wavelengths_nm lists {len(self.fbg.base_wavelengths_nm)} gratings, "
                f"sensor.grating_count is {self.sensor.grating_count}"
            )

    def compliance(self, tube: str | None) -> tuple[tuple[float, float], bool]:
        """The compliance (min, max) in m/N between the stage encoder and the sensor's clamp of
        ``tube`` (None: the bench-top stage), and whether it is calibrated (else the
        uncalibrated range)."""
        value = (
            self.calibration.stage_compliance_mm_per_n
            if tube is None
            else self.tube(tube).compliance_mm_per_n
        )
        calibrated = compliance_range(value)
        if calibrated is not None:
            return calibrated, True
        return (0.0, self.calibration.uncalibrated_compliance_max_mm_per_n * MM), False

    def tube(self, name: str) -> TubeConfig:
        for t in self.tubes:
            if t.name == name:
                return t
        raise KeyError(f"no tube named {name!r}; known: {[t.name for t in self.tubes]}")
