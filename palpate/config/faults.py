"""The fault section of a scene: which faults a fault campaign injects, and when.

A scene's ``faults`` section (``config/scenes/faults.yaml``) lists fault cases; ``palpate sim
--faults`` runs ``trials_per_case`` trials of the scene's campaign under each case and checks,
from the emulators and the logs, that every trial stopped safely and kept its data.

A case's scheduled faults start at its trigger: ``start`` (the trial's first tick) or ``contact``
(the first sample where the simulated world has the tip touching the tissue), plus ``delay_s``.
Probabilistic board faults (``board``: the keys of ``sim.board.BoardFaults``, checked when the
campaign starts) apply from the start; packet loss and corruption on the servo bus apply from
the trigger on.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Literal

from .loader import limits
from .optics import MM
from .units import SI

ServoName = Literal["outer_roll", "inner_roll", "translation"]
# Hardware Error Status bits by name (wire.dynamixel.HW_*).
HardwareError = Literal["input_voltage", "overheating", "encoder", "electrical_shock", "overload"]


@dataclass(frozen=True)
class FaultCase:
    """One fault (or a combination) injected into a trial."""

    name: str
    trigger: Literal["start", "contact"] = "contact"
    delay_s: float = field(default=0.0, metadata=limits(ge=0, le=600))
    servo: ServoName = "translation"  # the servo the servo faults below hit
    servo_timeout_s: float | None = field(default=None, metadata=limits(gt=0, le=600))
    corrupt_replies: int = field(default=0, metadata=limits(ge=0, le=1_000_000))
    packet_loss: float = field(default=0.0, metadata=limits(ge=0, le=1))
    corrupt_probability: float = field(default=0.0, metadata=limits(ge=0, le=1))
    hardware_error: tuple[HardwareError, ...] = ()
    stall: bool = False
    board: dict[str, Any] | None = None  # sim.board.BoardFaults keys
    stream_stops: bool = False  # the board goes silent at the trigger (unplugged)
    early_contact_mm: float = field(default=0.0, metadata=limits(ge=0, le=50))
    early_contact = SI("early_contact_mm", MM)  # m (palpate.config.units)
    tube_tip_stiffness_n_per_mm: float | None = field(default=None, metadata=limits(gt=0))
    kill: bool = False  # SIGKILL the process running the trial at the trigger


@dataclass(frozen=True)
class FaultsConfig:
    """The fault campaign: cases, each run on the first ``trials_per_case`` trials."""

    trials_per_case: int = field(default=2, metadata=limits(ge=1, le=1000))
    cases: tuple[FaultCase, ...] = ()

    def validate(self) -> None:
        names = [c.name for c in self.cases]
        if len(set(names)) != len(names):
            raise ValueError(f"cases: names must be unique, got {names}")
