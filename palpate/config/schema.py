"""Typed configuration: the YAML keys, their units, defaults from the paper, and ranges.

Field names are the YAML keys, so a non-SI key says its unit (``fiber_radius_mm``); the SI value is
a property without the suffix (``fiber_radius`` in m). Defaults are the paper's sensor and robot
(Moradkhani et al., "An FBG-based Stiffness Estimation Sensor for In-vivo Diagnostics").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from .drive import DriveConfig
from .loader import limits
from .optics import MM, NM, PM, UE, FbgConfig, TipGratingConfig
from .servo import ServoConfig
from .xystage import XYStageConfig

__all__ = [
    "DEFAULT_CONTROL_RATE_HZ",
    "GPA",
    "MM",
    "NM",
    "PM",
    "UE",
    "BoardConfig",
    "CalibrationConfig",
    "DriveConfig",
    "FbgConfig",
    "SensorConfig",
    "ServoBusConfig",
    "ServoConfig",
    "StackConfig",
    "TipGratingConfig",
    "TubeConfig",
    "XYStageConfig",
    "check_compliance",
    "compliance_range",
    "servo_roster",
]

GPA = 1e9

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
    # An optional force grating at the tip (null: the paper's sensor, without one)
    tip_grating: TipGratingConfig | None = None
    # The tissue moduli the sensor was designed for (`palpate design --write`); an estimate
    # whose interval lies wholly outside gets no number. null: not stated.
    designed_range_kpa: tuple[float, float] | None = field(
        default=None, metadata=limits(gt=0, le=1e7)
    )

    def validate(self) -> None:
        r = self.designed_range_kpa
        if r is not None and not r[0] < r[1]:
            raise ValueError(f"designed_range_kpa: [min, max] needs min < max, got {list(r)}")
        if not self.used_gratings:
            raise ValueError("used_gratings: at least one grating must be used")
        for g in self.used_gratings:
            if not 1 <= g <= self.grating_count:
                raise ValueError(f"used_gratings: grating {g} is not in 1..{self.grating_count}")
        if len(set(self.used_gratings)) != len(self.used_gratings):
            raise ValueError("used_gratings: a grating is listed twice")

    @property
    def designed_range(self) -> tuple[float, float] | None:
        """The designed moduli (Pa), or None."""
        r = self.designed_range_kpa
        return None if r is None else (r[0] * 1e3, r[1] * 1e3)

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
class BoardConfig:
    """The acquisition board's serial stream (frame format in docs/frame-protocol.md)."""

    port: str = "sim"
    baudrate: int = field(default=921600, metadata=limits(gt=0))
    rate_hz: float = field(default=1000.0, metadata=limits(gt=0, le=100000))
    stale_timeout_s: float = field(default=0.1, metadata=limits(gt=0, le=60))
    # a stream stale this long in a contact phase is lost: the trial faults and retracts
    # (shorter gaps hold the motion and resume, as a servo bus's missed replies do)
    lost_timeout_s: float = field(default=1.0, metadata=limits(gt=0, le=600))
    has_reference: bool = False
    has_force: bool = False

    def validate(self) -> None:
        if self.lost_timeout_s < self.stale_timeout_s:
            raise ValueError(
                f"lost_timeout_s: must be >= stale_timeout_s ({self.stale_timeout_s:g} s), got "
                f"{self.lost_timeout_s:g}"
            )


@dataclass(frozen=True)
class ServoBusConfig:
    """The Dynamixel bus: port, baud rate, and the three servos of the roller-gear drive.

    ``timeout_ms`` is how long the driver waits for a status packet beyond its transmission time;
    a transaction that fails on the wire is retried ``retries`` times. A read that still fails
    costs the trial one tick (the motion held, the tick's advance not recorded), not the trial:
    the bus is lost only after ``silence_ms`` without an answer (docs/transport-and-scale.md has
    the latencies these defaults are sized from). ``max_goal_step_deg`` is the safety clamp on
    how far a servo's goal may move in one control tick (shaft degrees).
    """

    port: str = "sim"
    baudrate: int = field(default=1000000, metadata=limits(gt=0))
    timeout_ms: float = field(default=20.0, metadata=limits(gt=0, le=10000))
    retries: int = field(default=3, metadata=limits(ge=0, le=20))
    silence_ms: float = field(default=250.0, metadata=limits(gt=0, le=10000))
    max_goal_step_deg: float = field(default=10.0, metadata=limits(gt=0, le=360))
    outer_roll: ServoConfig = ServoConfig(id=1)  # noqa: RUF009 - frozen
    inner_roll: ServoConfig = ServoConfig(id=2)  # noqa: RUF009 - frozen
    translation: ServoConfig = ServoConfig(id=3, model="XL430-W250")  # noqa: RUF009 - frozen

    def validate(self) -> None:
        ids = [self.outer_roll.id, self.inner_roll.id, self.translation.id]
        if len(set(ids)) != len(ids):
            raise ValueError(f"servo ids must differ, got {ids}")

    @property
    def timeout(self) -> float:
        return self.timeout_ms * 1e-3

    @property
    def silence(self) -> float:
        """How long the servos may not answer before the rig reports the bus lost (s)."""
        return self.silence_ms * 1e-3

    @property
    def max_goal_step(self) -> float:
        """Largest change of a servo goal per control tick, rad of servo shaft."""
        return math.radians(self.max_goal_step_deg)


def servo_roster(servos: ServoBusConfig, stage: XYStageConfig | None) -> dict[str, ServoConfig]:
    """Every servo on the bus by the name the drive and the stage use, in bus order: the
    roller-gear drive's three, then the x-y stage's two when the robot has one."""
    roster = {
        "outer_roll": servos.outer_roll,
        "inner_roll": servos.inner_roll,
        "translation": servos.translation,
    }
    if stage is not None:
        roster |= {"stage_x": stage.x, "stage_y": stage.y}
    return roster


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
    fbg: FbgConfig = FbgConfig()  # noqa: RUF009 - frozen
    board: BoardConfig = BoardConfig()
    servos: ServoBusConfig = ServoBusConfig()
    drive: DriveConfig = DriveConfig()  # noqa: RUF009 - frozen
    tubes: tuple[TubeConfig, ...] = DEFAULT_TUBES
    calibration: CalibrationConfig = CalibrationConfig()
    stage: XYStageConfig | None = None  # the x-y stage under the sample, for maps (optional)

    def validate(self) -> None:
        self._validate_tip_grating()
        self._validate_stage()
        names = [t.name for t in self.tubes]
        if len(set(names)) != len(names):
            raise ValueError(f"tubes: names must be unique, got {names}")
        if len(self.fbg.base_wavelengths_nm) < self.sensor.grating_count:
            raise ValueError(
                f"fbg.base_wavelengths_nm lists {len(self.fbg.base_wavelengths_nm)} gratings, "
                f"sensor.grating_count is {self.sensor.grating_count}"
            )

    def _validate_stage(self) -> None:
        if self.stage is None:
            return
        s = self.servos
        drive = {s.outer_roll.id, s.inner_roll.id, s.translation.id}
        for axis in ("x", "y"):
            servo_id = getattr(self.stage, axis).id
            if servo_id in drive:
                raise ValueError(
                    f"stage.{axis}.id: {servo_id} is a drive servo's id (servos.*): "
                    "the bus needs one id per servo"
                )

    def _validate_tip_grating(self) -> None:
        tip = self.sensor.tip_grating
        if tip is None or tip.temperature_compensation != "reference":
            return
        key = "sensor.tip_grating.temperature_compensation"
        if self.fbg.reference_wavelength_nm is None:
            raise ValueError(
                f"{key}: 'reference' needs a strain-free reference grating "
                "(fbg.reference_wavelength_nm)"
            )
        if not self.board.has_reference:
            raise ValueError(f"{key}: 'reference' needs the board to send it (board.has_reference)")

    def compliance(self, tube: str | None) -> tuple[tuple[float, float], bool]:
        """The compliance (min, max) in m/N between the stage encoder and the sensor's clamp of
        ``tube`` (None: the bench-top stage), and whether it is calibrated (else the
        uncalibrated range); a tip grating's element (``sensor.tip_grating.compliance_mm_per_n``)
        is added, travel that is not indentation either. A tube's calibrated value is the tube's
        own: a rigid reference's fit takes the element out (``estimation.fits.compliance.less``)."""
        value = (
            self.calibration.stage_compliance_mm_per_n
            if tube is None
            else self.tube(tube).compliance_mm_per_n
        )
        calibrated = compliance_range(value)
        element = 0.0 if self.sensor.tip_grating is None else self.sensor.tip_grating.compliance
        if calibrated is None:
            high = self.calibration.uncalibrated_compliance_max_mm_per_n * MM
            return (element, high + element), False
        if element == 0.0:
            return calibrated, True
        return (calibrated[0] + element, calibrated[1] + element), True

    def tube(self, name: str) -> TubeConfig:
        for t in self.tubes:
            if t.name == name:
                return t
        raise KeyError(f"no tube named {name!r}; known: {[t.name for t in self.tubes]}")
