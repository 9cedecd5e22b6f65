"""Each grating's thermal shift per the reference grating's, from a record through a temperature
change, and the residual a compensation leaves.

The strain-free reference grating (``fbg.reference_wavelength_nm``) reads the temperature alone;
a grating's shift in a free sensor is its ratio ``S_T,i / S_T,ref`` times the reference's. A
record of raw board frames with the sensor free (touching nothing) through a temperature change
of a few degrees or more (the insertion into the body, a water bath: ``cat /dev/ttyACM0 >
insertion.bin``) gives every ratio as a line through the pairs (reference shift, grating shift),
with an intercept (the zeros' own noise), so with its Student-t interval
(:func:`sensor.calibration.fit_strain_coefficient`): the strain gratings' (``fbg.thermal_ratios``)
and the tip grating's (``sensor.tip_grating.thermal_ratio``). The pairs are means over blocks of
``block_s`` (0.2 s): the reference's own noise, in the line's abscissa, would flatten the slope by
``sigma^2 / var(shift)`` (0.07 % on a 15 degC insertion at 1 pm of noise, as large as the
interval, which does not carry it); 50 frames a block make it 50 times smaller.

The residual (:func:`residuals`) is what a compensation leaves on each grating: the compensated
shift's means over windows (``window_s``, 1 s), the largest against the first. A record whose
temperature moved takes the configuration's ratios to task before (``configured``) and the
fitted ones after (``calibrated``); on a second record, the calibration's held-out residual.

Usage::

    fit = fit_thermal_frames(read_frames("insertion.bin", stack), stack)
    print(fit.config_lines(stack))
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..config.schema import StackConfig
from ..wire.frameblock import FrameBlock
from .calibration import CalibrationFit, fit_strain_coefficient
from .tipforce import TipForceChain

PM = 1e-12
MIN_SPAN_PM = 20.0  # the reference's least span to calibrate on: 2 degC at 10 pm/degC
FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class ThermalRecord:
    """A free sensor's shifts (m) against the record's first window: ``gratings`` (n, N) of the
    used gratings (``numbers``, 1-based), the tip grating's (n,) or None, the reference's (n,)."""

    numbers: tuple[int, ...]
    gratings: FloatArray
    tip: FloatArray | None
    reference: FloatArray
    time: FloatArray

    @property
    def span(self) -> float:
        """The reference's span over the record (m)."""
        return float(self.reference.max() - self.reference.min())

    def columns(self) -> list[tuple[str, FloatArray]]:
        """(label, shifts) per grating, the tip grating's last."""
        out = [(str(g), self.gratings[:, k]) for k, g in enumerate(self.numbers)]
        return out + ([] if self.tip is None else [("tip", self.tip)])


@dataclass(frozen=True)
class ThermalFit:
    """Each grating's ratio (its line, SI: slope dimensionless) and the residuals (m) the
    configured and the fitted ratios leave (see the module docstring)."""

    labels: tuple[str, ...]
    lines: tuple[CalibrationFit, ...]
    configured: tuple[float, ...]
    residual_configured: tuple[float, ...]
    residual_calibrated: tuple[float, ...]
    span: float  # the reference's span over the record, m
    duration: float  # s
    frames: int

    @property
    def ratios(self) -> tuple[float, ...]:
        return tuple(line.k_eps for line in self.lines)

    def as_dict(self) -> dict[str, object]:
        rows = [
            {
                "grating": label,
                "ratio": line.k_eps,
                "ci": list(line.ci),
                "configured_ratio": c,
                "residual_configured_pm": rc / PM,
                "residual_calibrated_pm": rf / PM,
            }
            for label, line, c, rc, rf in zip(
                self.labels,
                self.lines,
                self.configured,
                self.residual_configured,
                self.residual_calibrated,
                strict=True,
            )
        ]
        return {
            "frames": self.frames,
            "duration_s": self.duration,
            "reference_span_pm": self.span / PM,
            "gratings": rows,
        }

    def config_lines(self, stack: StackConfig) -> list[str]:
        """The robot configuration's lines that store the fitted ratios (gratings not in the
        record keep their configured ratio)."""
        fitted = dict(zip(self.labels, self.ratios, strict=True))
        fbg = stack.fbg
        every = list(fbg.ratios(tuple(range(1, len(fbg.base_wavelengths_nm) + 1))))
        for label, ratio in fitted.items():
            if label != "tip":
                every[int(label) - 1] = ratio
        lines = ["fbg.thermal_ratios: [" + ", ".join(f"{r:.5f}" for r in every) + "]"]
        if "tip" in fitted:
            lines.append(f"sensor.tip_grating.thermal_ratio: {fitted['tip']:.5f}")
        return lines


def thermal_record(
    block: FrameBlock, stack: StackConfig, *, window_s: float = 1.0
) -> ThermalRecord:
    """The shifts of a recorded stream against its first ``window_s`` (ValueError when it
    carries no reference grating, or its reference moved less than 2 degC's worth)."""
    ref = block.reference
    if ref is None:
        raise ValueError(
            "the frames carry no reference grating (board.has_reference: true, "
            "fbg.reference_wavelength_nm): nothing reads the temperature alone"
        )
    t = block.time - block.time[0]
    first = t < window_s
    if np.count_nonzero(~first) < 10:
        raise ValueError(f"{len(block)} frames over {t[-1]:.2f} s: record longer than {window_s} s")
    wl = block.wavelengths
    tip = None if stack.sensor.tip_grating is None else block.tip
    if tip is not None:
        tip = tip - tip[first].mean()
    used = stack.sensor.used_gratings
    record = ThermalRecord(used, wl - wl[first].mean(axis=0), tip, ref - ref[first].mean(), t)
    if record.span < MIN_SPAN_PM * PM:
        raise ValueError(
            f"the reference grating moved {record.span / PM:.1f} pm over the record: calibrate "
            f"across a temperature change of {MIN_SPAN_PM:.0f} pm (2 degC) or more (an insertion, "
            "a bath)"
        )
    return record


def residuals(
    record: ThermalRecord, ratios: tuple[float, ...], *, window_s: float = 1.0
) -> tuple[float, ...]:
    """The compensation's residual per column (m): each compensated shift's window means, the
    largest distance from the first window's."""
    windows = np.floor(record.time / window_s).astype(np.int64)
    out = []
    for (_, shift), ratio in zip(record.columns(), ratios, strict=True):
        means = _block_means(shift - ratio * record.reference, windows)
        out.append(float(np.max(np.abs(means - means[0]))))
    return tuple(out)


def _block_means(values: FloatArray, blocks: NDArray[np.int64]) -> FloatArray:
    """The means of ``values`` over each non-empty block."""
    counts = np.bincount(blocks)
    full = counts > 0
    means: FloatArray = np.bincount(blocks, weights=values)[full] / counts[full]
    return means


def fit_thermal_frames(
    block: FrameBlock,
    stack: StackConfig,
    *,
    confidence: float = 0.95,
    window_s: float = 1.0,
    block_s: float = 0.2,
) -> ThermalFit:
    """Each grating's ratio from a free sensor's record (see the module docstring)."""
    record = thermal_record(block, stack, window_s=window_s)
    columns = record.columns()
    blocks = np.floor(record.time / block_s).astype(np.int64)
    reference = _block_means(record.reference, blocks)
    lines = tuple(
        fit_strain_coefficient(reference, _block_means(shift, blocks), confidence=confidence)
        for _, shift in columns
    )
    configured = stack.fbg.ratios(record.numbers)
    tip = stack.sensor.tip_grating
    if record.tip is not None and tip is not None:
        configured += (TipForceChain.from_config(tip, stack.fbg).thermal_ratio,)
    fitted = tuple(line.k_eps for line in lines)
    return ThermalFit(
        labels=tuple(label for label, _ in columns),
        lines=lines,
        configured=configured,
        residual_configured=residuals(record, configured, window_s=window_s),
        residual_calibrated=residuals(record, fitted, window_s=window_s),
        span=record.span,
        duration=float(record.time[-1]),
        frames=len(block),
    )
