"""One Dynamixel servo as a configuration names it (the drive's, ``servos:``, and the x-y
stage's, ``stage:``); re-exported by :mod:`config.schema`."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

from .loader import limits


@dataclass(frozen=True)
class ServoConfig:
    """One Dynamixel servo: its bus ID and model (checked against the model number on connect)."""

    id: int = field(default=1, metadata=limits(ge=0, le=252))
    model: Literal["XM430-W350", "XL430-W250"] = "XM430-W350"
