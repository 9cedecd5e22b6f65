"""k'_eps from a recorded stream of raw board frames: the sensor buckled on a rigid reference.

The glued fiber's strain coefficient (paper Fig. 1d) is the slope of wavelength shift against
strain. Without a separate strain standard, the sensor itself supplies the strains: pressed on a
rigid reference on the bench-top stage (fixed exposed length L), every bit of stage advance past
contact x0 goes into the beam's end shortening e = u - x0 (a compliance of the stage only shifts
x0 once the beam has buckled, the load staying near P_cr), and the elastica gives each grating's
mean strain at that shortening (``estimation.beam.model.Beam.grating_strains``, bending and the
axial
-P/EA). The frames carry both sides: the stage encoder (u) and the peak wavelengths (the shift
from the first ``rest_frames`` frames, taken at rest).

The contact x0 is scanned on a grid over the record (the predicted strains tabulated once over e
and interpolated), the line shift = k'_eps * strain through the origin fitted at each x0, and the
best x0's pairs give the fit and its interval (``sensor.calibration.fit_strain_coefficient``;
the interval is the slope's at that x0). What it calibrates is the chain from curvature to
shift, i.e. k'_eps times the fiber's offset from the neutral axis as configured: exactly the
product the estimators use.

Record a stream with the board's port open in any serial tool (``cat /dev/ttyACM0 > frames.bin``)
while a trial indents a rigid reference; ``palpate calibrate frames.bin --exposed-length-mm L``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..config.schema import StackConfig
from ..estimation.beam.model import Beam
from ..estimation.beam.section import grating_intervals, sensor_section
from ..wire.dynamixel import TICKS_PER_REV
from ..wire.frameblock import FrameBlock, decode_block
from .calibration import CalibrationFit, fit_strain_coefficient
from .parser import layout_from_config

FloatArray = NDArray[np.float64]

X0_POINTS = 400
TABLE_POINTS = 4000
MIN_R_SQUARED = 0.9  # below, the shifts do not follow the elastica: no buckling in the record


def read_frames(path: str | Path, stack: StackConfig) -> FrameBlock:
    """The frames of a recorded byte stream with the configured layout (bad frames skipped).

    Raises:
        ValueError: naming the file, when it holds no valid frame.
    """
    data = Path(path).read_bytes()
    block, _ = decode_block(data, layout_from_config(stack.sensor, stack.board))
    if len(block) == 0:
        raise ValueError(f"{path}: no valid frame of the configured layout in the file")
    return block


def calibrate_frames(
    block: FrameBlock,
    stack: StackConfig,
    exposed_length: float,
    *,
    rest_frames: int = 20,
    confidence: float = 0.95,
) -> CalibrationFit:
    """k'_eps from frames recorded while the sensor (exposed length ``exposed_length``, m)
    buckles on a rigid reference (see the module docstring).

    Raises:
        ValueError: too few frames, or a record where the sensor never buckles.
    """
    if len(block) <= rest_frames + 10:
        raise ValueError(f"{len(block)} frames: too few (needs more than {rest_frames + 10})")
    s = stack.sensor
    beam = Beam.from_section(sensor_section(s), exposed_length)
    wavelengths = block.wavelengths
    shift = wavelengths - wavelengths[:rest_frames].mean(axis=0)
    u = block.encoder.astype(np.float64) * (stack.drive.lead / TICKS_PER_REV)
    e_grid, table = _strain_table(beam, grating_intervals(s, exposed_length), float(np.ptp(u)))
    best = None
    for x0 in np.linspace(float(u.min()), float(u.max()), X0_POINTS):
        strain = _predicted(u - x0, e_grid, table)
        sxx = float(np.sum(strain * strain))
        if sxx <= 0.0:
            continue
        k = float(np.sum(strain * shift)) / sxx
        rss = float(np.sum((shift - k * strain) ** 2))
        if best is None or rss < best[0]:
            best = (rss, strain)
    if best is None or not np.any(best[1] != 0.0):
        raise ValueError("the record never reaches buckling: no strain to calibrate against")
    fit = fit_strain_coefficient(
        best[1].reshape(-1), shift.reshape(-1), confidence=confidence, through_origin=True
    )
    if fit.r_squared < MIN_R_SQUARED:
        raise ValueError(
            f"the record never reaches buckling: the shifts do not follow the elastica's "
            f"strains (R^2 = {fit.r_squared:.3f} < {MIN_R_SQUARED})"
        )
    return fit


def _strain_table(beam: Beam, intervals: FloatArray, span: float) -> tuple[FloatArray, FloatArray]:
    """The grating strains (TABLE_POINTS, G) at end shortenings 0..min(span, max) (m)."""
    e = np.linspace(0.0, min(span, 0.99 * beam.max_shortening()), TABLE_POINTS)
    return e, beam.grating_strains(e, intervals, include_axial=True)


def _predicted(e: FloatArray, e_grid: FloatArray, table: FloatArray) -> FloatArray:
    """Strains (n, G) at shortenings ``e`` (0 before contact), interpolated in the table."""
    clipped = np.clip(e, 0.0, e_grid[-1])
    out = np.stack([np.interp(clipped, e_grid, table[:, g]) for g in range(table.shape[1])], 1)
    return np.where((e > 0.0)[:, None], out, 0.0)
