"""Stored poses ("targets"): where an operator left the sensor, by name, for scripted trials.

``palpate teleop`` saves the current pose under a name; ``palpate trial`` and scripted campaigns
read it back. The file is YAML (``config/targets.yaml`` is an example)::

    targets:
      - name: soft-downward        # unique
        tube: bent30               # a tube of the robot configuration
        roll_deg: 0.0              # roll of the tube about x
        translation_mm: 52.0       # stage translation at the stored pose
        note: sensor 1 mm above the soft sample

Saving replaces a target of the same name and writes the file atomically (a temporary file
renamed over the old one), so a crash while saving never loses the targets already stored.
"""

from __future__ import annotations

import dataclasses
import math
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from .loader import ConfigError, from_mapping, limits, load
from .schema import MM


@dataclass(frozen=True)
class TargetConfig:
    """One stored pose."""

    name: str
    tube: str
    roll_deg: float = field(metadata=limits(ge=-720, le=720))
    translation_mm: float = field(metadata=limits(ge=-1000, le=1000))
    note: str = ""

    @property
    def roll(self) -> float:
        return math.radians(self.roll_deg)

    @property
    def translation(self) -> float:
        return self.translation_mm * MM


@dataclass(frozen=True)
class TargetsFile:
    """The whole targets file."""

    targets: tuple[TargetConfig, ...] = ()

    def validate(self) -> None:
        names = [t.name for t in self.targets]
        dupes = sorted({n for n in names if names.count(n) > 1})
        if dupes:
            raise ValueError(f"targets: names must be unique, repeated: {dupes}")

    def get(self, name: str) -> TargetConfig:
        for t in self.targets:
            if t.name == name:
                return t
        known = [t.name for t in self.targets]
        raise KeyError(f"no target named {name!r}; known: {known}")


def load_targets(path: str | Path) -> TargetsFile:
    """Read a targets file; a missing file is an empty set of targets."""
    p = Path(path)
    if not p.exists():
        return TargetsFile()
    return load(TargetsFile, p)


def save_target(path: str | Path, target: TargetConfig) -> TargetsFile:
    """Add ``target`` (replacing one of the same name) and write the file atomically.

    Raises ConfigError (file and key) if the file there is not a targets file, or if the new
    target would not load back (a value out of range); the file is then left as it was.
    """
    p = Path(path)
    current = load_targets(p)
    kept = tuple(t for t in current.targets if t.name != target.name)
    updated = TargetsFile(targets=(*kept, target))
    data = {"targets": [dataclasses.asdict(t) for t in updated.targets]}
    from_mapping(TargetsFile, data, str(p))  # what is written must load back (no NaN, ranges)
    text = yaml.safe_dump(data, sort_keys=False)
    p.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", dir=p.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, p)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return updated


__all__ = ["ConfigError", "TargetConfig", "TargetsFile", "load_targets", "save_target"]
