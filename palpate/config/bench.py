"""The real bench: the robot configuration, serial ports and trials of ``config/bench.yaml``.

``palpate trial --config config/bench.yaml`` runs scripted trials at stored poses (targets, see
:mod:`config.targets`) on the servo bus and acquisition board named here; ``palpate teleop
--config config/bench.yaml`` jogs the same hardware. The indentation settings are the scenes'
:class:`config.scene.CampaignConfig` (stand-off, speeds, travel past contact, detector); its keys
that describe a *simulated* campaign (samples, tubes, orientations, exposed lengths) are rejected
here, because on the bench the ``trials`` list names the poses.

Relative file names (``robot``, ``targets``) are resolved like a scene's ``robot``: as given
(relative to the working directory) if that file exists, else the file shipped in ``config/``.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

from .loader import ConfigError, limits, load, resolve
from .sample import AssumedConfig
from .scene import CampaignConfig, check_patch, require_exposed_gratings, require_tip_grating
from .schema import DEFAULT_CONTROL_RATE_HZ, MM, StackConfig

SIMULATION_ONLY = ("samples", "exposed_lengths_mm", "exposed_length_mm", "tubes", "orientations")


@dataclass(frozen=True)
class PortConfig:
    """A serial port: a device path (``/dev/ttyUSB0``) or a pyserial URL; baud rate optional."""

    port: str
    baudrate: int | None = field(default=None, metadata=limits(gt=0))  # None: the robot's

    def validate(self) -> None:
        if not self.port.strip() or self.port == "sim":
            raise ValueError(
                f"port: {self.port!r} is not a device; name the serial port, e.g. /dev/ttyUSB0 "
                "(`palpate sim` and `palpate teleop` without --config run the simulator)"
            )


@dataclass(frozen=True)
class BenchTrialConfig:
    """One trial of the bench campaign: a stored pose and what is under it.

    ``assumed``: what the operator believes about the sample (``config.sample.AssumedConfig``:
    thickness, bonding, Poisson's ratio, a convex surface's radius, each a value, a range or
    ``unknown``); a key left out is ``unknown`` for the thickness, the bonding and the radius
    (a flat surface is fitted unless the touches show a sphere), and ``poisson`` for the
    Poisson ratio.
    ``rigid``: the pose faces a rigid reference; the trial calibrates the tube's (the stage's)
    compliance for the session's later trials instead of estimating a modulus.
    """

    target: str  # a name in the targets file: the stand-off pose (tube, roll, translation)
    sample: str = ""  # a label for the table and the log
    modulus_kpa: float | None = field(default=None, metadata=limits(gt=0, le=1e6))  # if known
    poisson: float = field(default=0.45, metadata=limits(ge=0, le=0.5))
    # bench-top (vertical stage) only: the fixed exposed length; null = sensor.exposed_length_mm
    exposed_length_mm: float | None = field(default=None, metadata=limits(gt=0, le=500))
    assumed: AssumedConfig | None = None
    rigid: bool = False

    @property
    def modulus(self) -> float | None:
        return None if self.modulus_kpa is None else self.modulus_kpa * 1e3

    @property
    def label(self) -> str:
        return self.sample or self.target


@dataclass(frozen=True)
class BenchMapConfig:
    """A stiffness map on the bench (issue 40; docs/maps.md): the x-y stage (``stage:`` of the
    robot file) puts the tip over each point of ``patch_mm`` (stage positions: the point of
    the sample under the tip) and every probe is a trial of the ``trials`` entry at ``target``
    (its sample, belief and stand-off pose). The plan picks the points (``strategy``), at most
    ``max_probes``; ``threshold_kpa`` is the map's level (null: half-way to the peak)."""

    target: str
    patch_mm: tuple[float, ...] = (-10.0, -10.0, 10.0, 10.0)
    strategy: Literal["active", "active-all", "raster", "random"] = "active"
    max_probes: int = field(default=30, metadata=limits(ge=1, le=10000))
    threshold_kpa: float | None = field(default=None, metadata=limits(gt=0))
    seed: int = field(default=0, metadata=limits(ge=0))

    def validate(self) -> None:
        check_patch(self.patch_mm, "patch_mm")

    @property
    def threshold(self) -> float | None:
        return None if self.threshold_kpa is None else self.threshold_kpa * 1e3


@dataclass(frozen=True)
class BenchConfig:
    """``config/bench.yaml``: the hardware and the scripted protocol."""

    servos: PortConfig  # the Dynamixel bus (U2D2 or similar)
    board: PortConfig  # the FBG acquisition board
    robot: str = "robot.yaml"
    targets: str = "targets.yaml"
    log_dir: str = "out/trial"
    control_rate_hz: float = field(default=DEFAULT_CONTROL_RATE_HZ, metadata=limits(gt=0, le=2000))
    after_trial: Literal["hold", "release"] = "hold"  # torque between trials
    stop_on_fault: bool = True
    retract_mm: float | None = field(default=None, metadata=limits(gt=0, le=500))
    campaign: CampaignConfig = field(default_factory=CampaignConfig)
    trials: tuple[BenchTrialConfig, ...] = ()
    map: BenchMapConfig | None = None  # a survey of a patch on the x-y stage (after the trials)

    def validate(self) -> None:
        if self.map is not None and not any(t.target == self.map.target for t in self.trials):
            raise ValueError(
                f"map.target: {self.map.target!r} is no trials entry's target (the entry says "
                "what each probe presses: its sample and belief)"
            )
        default = CampaignConfig()
        for key in SIMULATION_ONLY:
            if getattr(self.campaign, key) != getattr(default, key):
                raise ValueError(
                    f"campaign.{key}: describes a simulated campaign; on the bench list the "
                    "poses under trials (target names from the targets file)"
                )

    def retract_translation(self, standoff_translation: float, home_translation: float) -> float:
        """Where a trial starts and ends (m): the drive's home pose, or ``retract_mm`` behind
        the stand-off pose (never behind home)."""
        if self.retract_mm is None:
            return home_translation
        return max(home_translation, standoff_translation - self.retract_mm * MM)


@dataclass(frozen=True)
class LoadedBench:
    """A bench file with its robot configuration, ports applied, and where its files are."""

    path: Path
    bench: BenchConfig
    stack: StackConfig
    targets_path: Path


def load_bench(path: str | Path) -> LoadedBench:
    """Load a bench file and its robot configuration; the ports of the bench file override the
    robot's. Errors name the bench file and the key."""
    p = resolve(path)
    bench = load(BenchConfig, p)
    try:
        robot = resolve(bench.robot)
    except ConfigError:
        raise ConfigError(str(p), "robot", f"file not found: {bench.robot}") from None
    stack = load(StackConfig, robot)
    stack = dataclasses.replace(
        stack,
        servos=dataclasses.replace(
            stack.servos,
            port=bench.servos.port,
            baudrate=bench.servos.baudrate or stack.servos.baudrate,
        ),
        board=dataclasses.replace(
            stack.board,
            port=bench.board.port,
            baudrate=bench.board.baudrate or stack.board.baudrate,
        ),
    )
    _check_stage(p, bench, stack, robot)
    require_tip_grating(bench.campaign, stack, str(p), str(robot))
    _check_lengths(p, bench, stack, robot)
    targets = Path(bench.targets)
    if not targets.exists():
        try:
            targets = resolve(bench.targets)
        except ConfigError:
            targets = Path(bench.targets)  # teleop may create it; trial reports it missing
    return LoadedBench(p, bench, stack, targets)


def _check_stage(path: Path, bench: BenchConfig, stack: StackConfig, robot: Path) -> None:
    """A map needs the robot's x-y stage, and its patch inside the stage's travel."""
    if bench.map is None:
        return
    if stack.stage is None:
        raise ConfigError(
            str(path), "map", f"a map needs the x-y stage: {robot} has no stage: section"
        )
    x0, y0, x1, y1 = bench.map.patch_mm
    (xl, xh), (yl, yh) = stack.stage.x_travel_mm, stack.stage.y_travel_mm
    if x0 < xl or x1 > xh or y0 < yl or y1 > yh:
        raise ConfigError(
            str(path),
            "map.patch_mm",
            f"{list(bench.map.patch_mm)} reaches beyond the stage's travel "
            f"(x {[xl, xh]}, y {[yl, yh]} mm in {robot})",
        )


def _check_lengths(path: Path, bench: BenchConfig, stack: StackConfig, robot: Path) -> None:
    """On the bench-top column, each trial's fixed exposed length (or the sensor's own, in the
    robot file, where a trial gives none) must expose every grating the estimator reads."""
    if bench.campaign.on_tubes:
        return
    given = [
        (f"trials[{i}].exposed_length_mm", t.exposed_length_mm * MM)
        for i, t in enumerate(bench.trials)
        if t.exposed_length_mm is not None
    ]
    require_exposed_gratings(given, stack, str(path), str(robot))
    if len(given) < len(bench.trials):
        own = [("sensor.exposed_length_mm", stack.sensor.exposed_length)]
        require_exposed_gratings(own, stack, str(robot), str(robot))
