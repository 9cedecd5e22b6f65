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
from .scene import CampaignConfig
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

    def validate(self) -> None:
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
    targets = Path(bench.targets)
    if not targets.exists():
        try:
            targets = resolve(bench.targets)
        except ConfigError:
            targets = Path(bench.targets)  # teleop may create it; trial reports it missing
    return LoadedBench(p, bench, stack, targets)
