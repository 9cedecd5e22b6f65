"""Scenes: what the simulator builds (samples, fidelity switches) and the campaign it runs.

A scene file (``config/scenes/*.yaml``) names the robot configuration it uses, the tissue
samples, the fidelity switches (each effect costs nothing when off) and the campaign. The
defaults reproduce the paper: Table I's 11 phantoms for the bench-top campaign, Table II's two
samples for the robot campaign.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal

from .breathing import BreathingConfig
from .faults import FaultsConfig
from .loader import ConfigError, limits
from .optics import MM, PM, UE
from .sample import PAPER_SAMPLES, SampleConfig
from .schema import DEFAULT_CONTROL_RATE_HZ, StackConfig
from .thermal import TemperatureConfig
from .units import SI, SIOptional, SITuple

Orientation = Literal["downward", "sideways", "upward"]
ORIENTATION_ROLL_DEG: dict[str, float] = {"downward": 0.0, "sideways": 90.0, "upward": 180.0}


@dataclass(frozen=True)
class FidelityConfig:
    """Effects the simulated world models. Off means not computed at all.

    Always on, because they are the hardware itself: the stage is read through the servo's
    4096 ticks/rev encoder, and the emulated servos follow goals with profile velocity and
    acceleration (tracking lag).
    """

    fbg_noise_pm: float = field(default=1.0, metadata=limits(ge=0, le=1000))
    contact_uncertainty_mm: float = field(default=0.0, metadata=limits(ge=0, le=10))
    imperfection_w0_over_l: float = field(default=0.0, metadata=limits(ge=0, le=0.1))
    finite_thickness: bool = True
    large_indentation: bool = True
    tube_tip_stiffness_n_per_mm: float | None = field(default=None, metadata=limits(gt=0))
    temperature_drift_degc_per_s: float = field(default=0.0, metadata=limits(ge=-10, le=10))
    # An insertion's temperature step and each grating's own thermal shift (config/thermal.py);
    # null: one coefficient for every grating, the drift alone.
    temperature: TemperatureConfig | None = None
    # The surface's motion with the breath, the ventilator's holds and the heart
    # (config/breathing.py); null: the tissue stands still.
    breathing: BreathingConfig | None = None
    # The tissue's force law (sim/sample_law.py): "fe", each sample's own finite-element table
    # (sim/fem; independent of the estimator, so the default: a world that shares the
    # estimator's model measures self-consistency, not accuracy; tables of the shipped scenes
    # ship with the package, others are solved once, 6-25 s, and cached); "closed-form",
    # Sneddon's sphere with the thin-layer series, the estimator's own family of laws (cheap;
    # a scene that picks it judges the estimator on its own model). finite_thickness: false
    # makes the FE layer a half-space stand-in; large_indentation applies to the closed form.
    tissue_model: Literal["fe", "closed-form"] = "fe"
    # The samples' standard-linear-solid relaxation (relaxation_time_s, relaxed_ratio); off, or a
    # sample without a relaxation time: elastic. Stepped on the virtual clock (slower per trial).
    viscoelastic: bool = False
    # The reported reference moduli (the paper's "actual" column) were themselves measured
    # (cylindrical indenter, McKee et al. 2011): relative sd of their lognormal error against the
    # world's truth, drawn per sample from the campaign seed. 0: the reference is the truth.
    reference_error_sd: float = field(default=0.0, metadata=limits(ge=0, le=1))
    gravity: bool = False  # gravity on the sensor beam and the tubes (pre-bend, tip sag)
    # The servo bus's time on the virtual clock (sim/dynamixel/timing.py): "ideal" answers at
    # once; "realistic" adds wire time at the baud rate (null: the robot's servos.baudrate), each
    # servo's Return_Delay_Time and the USB adapter's latency timer (Linux FTDI default 16 ms).
    bus_timing: Literal["ideal", "realistic"] = "ideal"
    bus_baudrate: int | None = field(default=None, metadata=limits(gt=0, le=10_500_000))
    latency_timer_ms: float = field(default=16.0, metadata=limits(ge=1, le=255))
    # The contact table's grid along the advance past contact (um; sim/contact_table.py). null
    # (default): the stage encoder's lattice, so every lookup lands on a solved point (exact);
    # a coarser grid (rounded to whole encoder counts) solves fewer equilibria per trial and
    # interpolates linearly between them: a cheaper world, for speed-over-accuracy levels.
    contact_grid_um: float | None = field(default=None, metadata=limits(gt=0, le=1000))
    # A sample with inclusions seen from a point the 3-D tables were not solved at: solve
    # there ("exact", 10-100 s a new distance), interpolate one inclusion between solves at
    # fixed distances ("interpolated", sim/fem3d/offsets.py), or factorise the whole patch once
    # and press anywhere on it ("patch", sim/fem3d/patch.py: any number of inclusions, about a
    # minute a geometry, milliseconds a point; docs/maps.md).
    inclusion_offsets: Literal["exact", "interpolated", "patch"] = "exact"
    # The patch of the sample's surface (mm, [x_min, y_min, x_max, y_max] of the tip's centre)
    # that "patch" meshes finely (a map's campaign.patch_mm must lie inside it).
    inclusion_patch_mm: tuple[float, ...] = (-10.0, -10.0, 10.0, 10.0)

    # the SI views of the unit-suffixed fields (palpate.config.units)
    fbg_noise = SI("fbg_noise_pm", PM)  # m of wavelength
    contact_uncertainty = SI("contact_uncertainty_mm", MM)
    tube_tip_stiffness = SIOptional("tube_tip_stiffness_n_per_mm", 1.0 / MM)  # N/m
    latency_timer = SI("latency_timer_ms", 1e-3)  # s
    contact_grid = SIOptional("contact_grid_um", 1e-6)  # m


@dataclass(frozen=True)
class CampaignConfig:
    """Which trials to run and how each one indents."""

    kind: Literal["bench", "robot", "map"] = "robot"
    samples: tuple[str, ...] = ()  # empty: every sample of the scene
    exposed_lengths_mm: tuple[float, ...] = field(  # bench-top; each as exposed_length_mm
        default=(42.0, 44.0, 46.0, 48.0, 50.0), metadata=limits(gt=0, le=500)
    )
    exposed_length_mm: float = field(default=42.0, metadata=limits(gt=0, le=500))  # robot
    # A trial that buckles and gives no estimate (beside the heart, whose systole buckles a long
    # beam on a stiff sample within its own excursion) runs again at each of these shorter
    # exposed lengths in turn, until one gives an estimate (campaigns/shorter.py); empty: never.
    retry_lengths_mm: tuple[float, ...] = field(default=(), metadata=limits(gt=0, le=500))
    tubes: tuple[str, ...] = ("straight", "bent15", "bent30", "bent50")
    orientations: tuple[Orientation, ...] = ("downward", "sideways", "upward")
    repeats: int = field(default=1, metadata=limits(ge=1, le=1000))
    standoff_mm: float = field(default=1.0, metadata=limits(gt=0, le=50))
    approach_speed_mm_per_s: float = field(default=2.0, metadata=limits(gt=0, le=100))
    indent_speed_mm_per_s: float = field(default=0.5, metadata=limits(gt=0, le=100))
    # Each trial at each of these speeds instead (a viscoelastic scene's speed sweep); empty:
    # indent_speed_mm_per_s alone.
    indent_speeds_mm_per_s: tuple[float, ...] = field(default=(), metadata=limits(gt=0, le=100))
    # Approach at the indentation speed instead of approach_speed_mm_per_s: one constant-rate
    # ramp through the contact, the history a relaxing tissue's fit needs (docs/viscoelastic.md).
    ramp_through_contact: bool = False
    post_buckling_mm: float = field(default=0.3, metadata=limits(ge=0, le=20))
    # Stand still this long after the post-buckling travel: a creep test the gratings record, from
    # which the estimator reads the relaxed and instantaneous moduli (estimation.relaxation);
    # 0: no hold (an elastic sample needs none). docs/viscoelastic.md has the length's table.
    hold_s: float = field(default=0.0, metadata=limits(ge=0, le=50))
    max_travel_past_contact_mm: float = field(default=2.5, metadata=limits(gt=0, le=50))
    contact: Literal["event", "fbg", "tip"] = "event"
    # paper: the strain norm past detector_threshold_ue; cusum: the first mode's CUSUM; tip: the
    # tip grating's load stops rising (estimation.detect.plateau; a sagging mN beam, docs/invivo.md)
    detector: Literal["paper", "cusum", "tip"] = "paper"
    detector_threshold_ue: float = field(default=300.0, metadata=limits(gt=0, le=10000))
    outlier_above_kpa: float = field(default=3000.0, metadata=limits(gt=0))
    # A diagnostic threshold (normal below, diseased above): `palpate sim` counts the trials with
    # a number on its right side (null: no threshold)
    classify_at_kpa: float | None = field(default=None, metadata=limits(gt=0))

    @property
    def classify_at(self) -> float | None:
        """The diagnostic threshold in Pa, or None."""
        return None if self.classify_at_kpa is None else self.classify_at_kpa * 1e3  # kPa -> Pa

    # Find the surface normal by light touches before indenting (robot.probing), then re-plan
    # the roll and advance orthogonal to it; null: on for robot campaigns, off on the vertical
    # bench stage. "measure": touch, fit and log the misalignment, but indent as planned.
    probe: bool | Literal["measure"] | None = None
    misalignment_tolerance_deg: float = field(default=2.0, metadata=limits(gt=0, le=45))
    # The surface's motion along the axis a trial tolerates between the first touch and the
    # release, measured from the tip grating (estimation/pose/motion.py: breathing, the heart); a
    # trial that moved more is not ok. null: not checked.
    motion_tolerance_mm: float | None = field(default=None, metadata=limits(gt=0, le=50))
    # "board": wait at the stand-off for the ventilator's breath hold (frame status bit 6, the
    # world's fidelity.breathing.gate), indent within it (robot/indentation.py); "none": go.
    gate: Literal["none", "board"] = "none"

    @property
    def gated(self) -> bool:
        """A trial waits for the board's breath-hold gate and indents in the hold."""
        return self.gate == "board"

    # The orthogonal contact must lie this close to where the plan aimed (on the sample).
    miss_tolerance_mm: float = field(default=30.0, metadata=limits(gt=0, le=500))
    probe_points: int = field(default=4, metadata=limits(ge=3, le=9))  # touches; >= 5: spheres
    # How far the touches' arc bows across the roll (a roll moves the tip on a circle about the
    # x axis): what fixes the normal's tilt along the tube's bend, so the roll span per tube.
    probe_sagitta_mm: float = field(default=3.0, metadata=limits(gt=0, le=50))
    probe_touch_ue: float = field(default=25.0, metadata=limits(gt=0, le=1000))  # light touch
    # kind: map (palpate map, docs/maps.md): the patch of the sample's surface it surveys
    # (x_min, y_min, x_max, y_max, mm, from where a single trial indents), the plan, the probe
    # budget, the level set's modulus (null: from the data), and the x-y stage's speed between
    # probes (its travel counts in the map's lab time). Each probe indents on the bench column
    # at the first of exposed_lengths_mm.
    patch_mm: tuple[float, ...] = (-10.0, -10.0, 10.0, 10.0)
    strategy: Literal["active", "active-all", "raster", "random"] = "active"
    max_probes: int = field(default=30, metadata=limits(ge=1, le=10000))
    map_threshold_kpa: float | None = field(default=None, metadata=limits(gt=0))
    stage_speed_mm_per_s: float = field(default=5.0, metadata=limits(gt=0, le=1000))
    # How a map's probe reaches its point: "stage" (the x-y stage slides the sample under the
    # bench column) or "robot" (the tissue stays and a positioner carries the robot: each probe a
    # robot trial, its tube, roll and stage pose from robot.positioner.place, square on to the
    # patch's plane; campaigns/throughrobot.py). The plane faces the robot's insertion axis,
    # tilted map_tilt_deg toward +z (a tube of that tip angle at roll 0 meets it square on); the
    # positioner travels +-positioner_travel_mm on each axis at stage_speed_mm_per_s.
    map_through: Literal["stage", "robot"] = "stage"
    map_tilt_deg: float = field(default=0.0, metadata=limits(ge=0, le=80))
    positioner_travel_mm: float = field(default=30.0, metadata=limits(gt=0, le=500))

    def speeds_mm_per_s(self) -> tuple[float, ...]:
        """The indentation speeds the campaign runs each trial at (mm/s)."""
        return self.indent_speeds_mm_per_s or (self.indent_speed_mm_per_s,)

    def lengths_pressed(self) -> tuple[float, ...]:
        """The exposed lengths (m, at contact) the campaign's trials press at first."""
        return (self.exposed_length,) if self.on_tubes else self.exposed_lengths

    @property
    def on_tubes(self) -> bool:
        """A robot campaign (the trials advance on the robot's tubes), not the bench column."""
        return self.kind == "robot"

    def probing(self) -> bool | Literal["measure"]:
        """Whether trials probe: ``probe`` itself, or for null, robot campaigns only."""
        return self.kind == "robot" if self.probe is None else self.probe

    # the SI views of the unit-suffixed fields (palpate.config.units)
    exposed_lengths = SITuple("exposed_lengths_mm", MM)
    exposed_length = SI("exposed_length_mm", MM)
    retry_lengths = SITuple("retry_lengths_mm", MM)
    standoff = SI("standoff_mm", MM)
    approach_speed = SI("approach_speed_mm_per_s", MM)  # m/s
    indent_speed = SI("indent_speed_mm_per_s", MM)
    indent_speeds = SITuple("indent_speeds_mm_per_s", MM)
    post_buckling = SI("post_buckling_mm", MM)
    max_travel_past_contact = SI("max_travel_past_contact_mm", MM)
    detector_threshold = SI("detector_threshold_ue", UE)  # strain
    outlier_above = SI("outlier_above_kpa", 1e3)  # Pa
    misalignment_tolerance = SI("misalignment_tolerance_deg", math.pi / 180)  # rad
    motion_tolerance = SIOptional("motion_tolerance_mm", MM)  # m
    miss_tolerance = SI("miss_tolerance_mm", MM)
    probe_sagitta = SI("probe_sagitta_mm", MM)
    probe_touch = SI("probe_touch_ue", UE)
    stage_speed = SI("stage_speed_mm_per_s", MM)  # m/s
    map_tilt = SI("map_tilt_deg", math.pi / 180)  # rad
    positioner_travel = SI("positioner_travel_mm", MM)

    @property
    def map_threshold(self) -> float | None:
        """The map's level set in Pa, or None (from the data)."""
        return None if self.map_threshold_kpa is None else self.map_threshold_kpa * 1e3


@dataclass(frozen=True)
class SceneConfig:
    """A simulated world and the campaign to run in it: ``config/scenes/*.yaml``."""

    name: str = "scene"
    robot: str = "robot.yaml"
    transport: Literal["fast", "wire"] = "fast"
    control_rate_hz: float = field(default=DEFAULT_CONTROL_RATE_HZ, metadata=limits(gt=0, le=10000))
    # The acquisition board's frame rate in this scene; null: the robot configuration's. The
    # control loop uses the newest frame of each tick, so frames beyond the control rate are
    # computed, sent and parsed only to be dropped: a campaign scene streams at its control rate.
    board_rate_hz: float | None = field(default=None, metadata=limits(gt=0, le=100000))
    samples: tuple[SampleConfig, ...] = PAPER_SAMPLES
    fidelity: FidelityConfig = FidelityConfig()
    campaign: CampaignConfig = CampaignConfig()
    faults: FaultsConfig = field(default_factory=FaultsConfig)  # for ``palpate sim --faults``
    # Each trial's MCAP recording beside its log (robot/records/recording.py; docs/recordings.md):
    # about a sixth of a simulated trial's CPU; ``palpate sim --no-mcap`` turns it off.
    mcap: bool = True

    def validate(self) -> None:
        names = [s.name for s in self.samples]
        if len(set(names)) != len(names):
            raise ValueError(f"samples: names must be unique, got {names}")
        for k, sample in enumerate(self.samples):
            if sample.inclusions and self.fidelity.tissue_model != "fe":
                raise ValueError(
                    f"samples[{k}].inclusions: the world feels inclusions only on "
                    f"fidelity.tissue_model: fe (got {self.fidelity.tissue_model!r})"
                )
        for wanted in self.campaign.samples:
            if wanted not in names:
                raise ValueError(f"campaign.samples: no sample named {wanted!r}; known: {names}")
        if self.fidelity.inclusion_offsets == "interpolated":
            for k, sample in enumerate(self.samples):
                if len(sample.inclusions) > 1:
                    raise ValueError(
                        f"samples[{k}].inclusions: fidelity.inclusion_offsets: interpolated "
                        "holds one inclusion a sample"
                    )
        if self.fidelity.inclusion_offsets == "patch":
            _check_world_patch(self)
        if self.campaign.kind == "map":
            _check_map(self)
        longest = max(self.campaign.lengths_pressed(), default=0.0)
        for i, length in enumerate(self.campaign.retry_lengths):
            if length >= longest:
                raise ValueError(
                    f"campaign.retry_lengths_mm[{i}]: {length / MM:g} mm is no shorter than the "
                    f"trials' {longest / MM:g} mm: a retry runs at a shorter exposed length"
                )

    def campaign_samples(self) -> tuple[SampleConfig, ...]:
        wanted = self.campaign.samples
        return tuple(s for s in self.samples if not wanted or s.name in wanted)


def require_tip_grating(
    campaign: CampaignConfig, stack: StackConfig, source: str, robot: str
) -> None:
    """ConfigError naming ``source`` and the key where ``campaign`` reads its contact or its
    buckling from a tip grating (``'tip'``) that the sensor of ``stack`` (from ``robot``) lacks:
    ``palpate sim``'s preflight and ``palpate trial``'s bench file alike."""
    if stack.sensor.tip_grating is not None:
        return
    for key in ("contact", "detector"):
        if getattr(campaign, key) == "tip":
            raise ConfigError(
                source,
                f"campaign.{key}",
                f"'tip' needs a tip force grating: {robot} has no sensor.tip_grating",
            )


def require_exposed_gratings(
    lengths: Sequence[tuple[str, float]], stack: StackConfig, source: str, robot: str
) -> None:
    """ConfigError naming ``source`` and the key of the first exposed length (key, m) that
    leaves a grating the estimator reads inside the tube: its strains would be the tube's, and
    every trial would end with no estimate (``palpate sim``'s campaign and the bench file's
    trials alike)."""
    sensor = stack.sensor
    reach = max(sensor.grating_centres_from_tip()) + 0.5 * sensor.grating_length
    for key, length in lengths:
        if length < reach - 1e-12:
            raise ConfigError(
                source,
                key,
                f"{length / MM:g} mm leaves a grating inside the tube: the estimator reads "
                f"gratings {list(sensor.used_gratings)} of {robot}, the farthest ending "
                f"{reach / MM:g} mm from the tip; expose at least {reach / MM:g} mm",
            )


def campaign_lengths(campaign: CampaignConfig) -> list[tuple[str, float]]:
    """(key, m) of the exposed lengths a simulated ``campaign`` presses at (at contact)."""
    retry = [
        (f"campaign.retry_lengths_mm[{i}]", length)
        for i, length in enumerate(campaign.retry_lengths)
    ]
    if campaign.on_tubes:
        return [("campaign.exposed_length_mm", campaign.exposed_length), *retry]
    return [
        (f"campaign.exposed_lengths_mm[{i}]", length)
        for i, length in enumerate(campaign.exposed_lengths)
    ] + retry


def check_patch(patch_mm: tuple[float, ...], key: str) -> None:
    """A map's patch: four corners in order (ValueError naming ``key``)."""
    if len(patch_mm) != 4 or not (patch_mm[2] > patch_mm[0] and patch_mm[3] > patch_mm[1]):
        raise ValueError(
            f"{key}: [x_min, y_min, x_max, y_max] with x_max > x_min and y_max > "
            f"y_min, got {list(patch_mm)}"
        )


def _check_world_patch(scene: SceneConfig) -> None:
    """``fidelity.inclusion_patch_mm``: four corners in order, holding a map's patch."""
    world = scene.fidelity.inclusion_patch_mm
    check_patch(world, "fidelity.inclusion_patch_mm")
    if scene.campaign.kind != "map":
        return
    x0, y0, x1, y1 = scene.campaign.patch_mm
    if x0 < world[0] or y0 < world[1] or x1 > world[2] or y1 > world[3]:
        raise ValueError(
            f"fidelity.inclusion_patch_mm: {list(world)} must hold the map's campaign.patch_mm "
            f"{list(scene.campaign.patch_mm)} (the world is meshed finely only there)"
        )


def _check_map(scene: SceneConfig) -> None:
    """A map campaign's keys: a patch of four corners in order, one sample."""
    c = scene.campaign
    check_patch(c.patch_mm, "campaign.patch_mm")
    if len(scene.campaign_samples()) != 1:
        names = [s.name for s in scene.campaign_samples()]
        raise ValueError(f"campaign.samples: a map surveys one sample, got {names}")
    if c.map_through == "stage" and c.map_tilt_deg != 0.0:
        raise ValueError(
            "campaign.map_tilt_deg: the x-y stage's column meets only a level patch; a tilted "
            "one needs campaign.map_through: robot"
        )
