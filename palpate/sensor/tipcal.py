"""The tip force grating's sensitivity, calibrated against a force scale, with an interval.

Two sources, one line: the tip grating's shift against the force on it, ``shift = s F + c``
(the intercept takes up the zeros' own noise):

- a CSV with ``force_mn`` and ``shift_pm`` columns (the scale's reading and the grating's shift,
  however they were logged);
- a recorded stream of raw board frames that carry both the tip grating (options bit 2) and the
  force scale's reading (bit 1), recorded while the sensor presses on the scale
  (``cat /dev/ttyACM0 > frames.bin``): the shift from the first ``rest_frames`` frames, the
  reference grating's shift taken out (scaled by the two thermal coefficients) when the tip
  grating is compensated, frames whose force is not flagged fresh (``FORCE_VALID``) skipped.

The fit and its Student-t interval are :func:`sensor.calibration.fit_strain_coefficient`'s
(a line is a line); :class:`TipSensitivityFit` says it in pm/mN.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..config.schema import StackConfig
from ..wire.frame import Status
from ..wire.frameblock import FrameBlock
from .calibration import CalibrationFit, fit_strain_coefficient, load_pairs_csv
from .tipforce import TipForceChain

PM_PER_MN = 1e-12 / 1e-3  # m/N in one pm/mN
COLUMNS = ("force_mn", "shift_pm")


@dataclass(frozen=True)
class TipSensitivityFit:
    """The tip grating's sensitivity (pm/mN) with its interval, and the line's fit (SI)."""

    line: CalibrationFit

    @property
    def sensitivity_pm_per_mn(self) -> float:
        return self.line.k_eps / PM_PER_MN

    @property
    def ci_pm_per_mn(self) -> tuple[float, float]:
        return (self.line.ci[0] / PM_PER_MN, self.line.ci[1] / PM_PER_MN)

    def as_dict(self) -> dict[str, object]:
        return {
            "sensitivity_pm_per_mn": self.sensitivity_pm_per_mn,
            "ci_pm_per_mn": list(self.ci_pm_per_mn),
            "intercept_pm": self.line.intercept / 1e-12,
            "r_squared": self.line.r_squared,
            "residual_std_pm": self.line.residual_std / 1e-12,
            "n": self.line.n,
            "confidence": self.line.confidence,
        }

    def config_line(self) -> str:
        return f"sensor.tip_grating.sensitivity_pm_per_mn: {self.sensitivity_pm_per_mn:.4g}"


def fit_tip_csv(path: str | Path, *, confidence: float = 0.95) -> TipSensitivityFit:
    """The sensitivity from a ``force_mn``/``shift_pm`` CSV; ValueError naming the file."""
    force, shift = load_pairs_csv(path, COLUMNS, (1e-3, 1e-12))
    try:
        return TipSensitivityFit(fit_strain_coefficient(force, shift, confidence=confidence))
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from None


def fit_tip_frames(
    block: FrameBlock,
    stack: StackConfig,
    *,
    rest_frames: int = 20,
    confidence: float = 0.95,
) -> TipSensitivityFit:
    """The sensitivity from raw frames carrying the tip grating and the force scale (see the
    module docstring); ValueError when the frames cannot give one."""
    tip = stack.sensor.tip_grating
    if tip is None:
        raise ValueError("the robot configuration has no sensor.tip_grating to calibrate")
    wl = block.tip
    if wl is None or block.force_un is None:
        raise ValueError(
            "the frames must carry the tip grating and the force scale (board.has_force: true)"
        )
    if len(block) <= rest_frames + 10:
        raise ValueError(f"{len(block)} frames: too few (needs more than {rest_frames + 10})")
    shift = wl - wl[:rest_frames].mean()
    if tip.temperature_compensation == "reference":
        ref = block.reference
        if ref is None:
            raise ValueError("a compensated tip grating needs the reference grating in the frames")
        ratio = TipForceChain.from_config(tip, stack.fbg).thermal_ratio
        shift = shift - ratio * (ref - ref[:rest_frames].mean())
    force = block.force_un.astype(np.float64) * 1e-6
    fresh = (block.flags & int(Status.FORCE_VALID)) != 0
    fresh[:rest_frames] = False
    if np.count_nonzero(fresh) < 10:
        raise ValueError("fewer than 10 frames with a fresh force reading past the rest frames")
    # with an intercept: the zero taken on the rest frames has noise of its own, which a line
    # through the origin would turn into a slope error its interval does not carry
    return TipSensitivityFit(
        fit_strain_coefficient(force[fresh], shift[fresh], confidence=confidence)
    )


def is_tip_csv(path: Path, columns: list[str]) -> bool:
    """Whether a calibration CSV is the tip grating's (its header names ``force_mn``)."""
    return path.suffix.lower() == ".csv" and COLUMNS[0] in columns
