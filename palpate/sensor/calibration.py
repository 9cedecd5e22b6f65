"""Calibration of the glued fiber's strain coefficient k'_eps from paired (strain, shift) data.

The paper glued its fiber and re-measured the coefficient (Fig. 1d): a line through paired known
strains and measured wavelength shifts, slope 0.424 pm/ue instead of the bare 1.2 pm/ue. This
module fits that line by ordinary least squares with a Student-t confidence interval on the
slope and the coefficient of determination R^2.

Recorded files are CSV with a header row naming ``strain_ue`` and ``shift_pm`` (other columns are
ignored; ``#`` starts a comment line).
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

# scipy.special, not scipy.stats: the same quantile without stats' 0.5 s import on every CLI start
from scipy.special import stdtrit  # type: ignore[import-untyped]  # scipy ships no types

UE = 1e-6
PM = 1e-12


@dataclass(frozen=True)
class CalibrationFit:
    """Result of :func:`fit_strain_coefficient` (SI: k_eps in m per unit strain, shift in m)."""

    k_eps: float
    ci: tuple[float, float]
    intercept: float
    r_squared: float
    residual_std: float
    n: int
    confidence: float
    through_origin: bool

    @property
    def k_pm_per_ue(self) -> float:
        return self.k_eps * UE / PM

    @property
    def ci_pm_per_ue(self) -> tuple[float, float]:
        return (self.ci[0] * UE / PM, self.ci[1] * UE / PM)

    def as_dict(self) -> dict[str, float | int | bool | list[float]]:
        return {
            "k_pm_per_ue": self.k_pm_per_ue,
            "ci_pm_per_ue": list(self.ci_pm_per_ue),
            "intercept_pm": self.intercept / PM,
            "r_squared": self.r_squared,
            "residual_std_pm": self.residual_std / PM,
            "n": self.n,
            "confidence": self.confidence,
            "through_origin": self.through_origin,
        }


def fit_strain_coefficient(
    strain: ArrayLike,
    shift: ArrayLike,
    *,
    confidence: float = 0.95,
    through_origin: bool = False,
) -> CalibrationFit:
    """Fit ``shift = k_eps * strain (+ intercept)``; strain dimensionless, shift in m, shapes (n,).

    Raises ValueError on mismatched shapes, non-finite values, too few points (n must exceed the
    number of fitted parameters) or strains that do not vary.
    """
    x = np.asarray(strain, dtype=np.float64).reshape(-1)
    y = np.asarray(shift, dtype=np.float64).reshape(-1)
    if x.shape != y.shape:
        raise ValueError(f"strain and shift differ in length: {x.shape[0]} vs {y.shape[0]}")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
        raise ValueError("strain and shift must be finite")
    if not 0 < confidence < 1:
        raise ValueError(f"confidence must be in (0, 1), got {confidence}")
    params = 1 if through_origin else 2
    n = x.shape[0]
    if n <= params:
        raise ValueError(f"need more than {params} points, got {n}")
    try:  # absurd values (1e300) overflow the sums of squares: an input error, not k = 0
        with np.errstate(over="raise", invalid="raise"):
            return _fit(x, y, confidence, through_origin, n - params)
    except FloatingPointError:
        raise ValueError(
            "strain and shift values out of range (the fit overflows): "
            f"|strain| up to {np.max(np.abs(x)):.3g}, |shift| up to {np.max(np.abs(y)):.3g} m"
        ) from None


def _fit(
    x: np.ndarray, y: np.ndarray, confidence: float, through_origin: bool, dof: int
) -> CalibrationFit:
    """The least-squares line and its interval (see :func:`fit_strain_coefficient`)."""
    n = x.shape[0]
    if through_origin:
        sxx = float(x @ x)
        if sxx == 0:
            raise ValueError("all strains are zero: the slope is undetermined")
        k = float(x @ y) / sxx
        intercept = 0.0
        ss_tot = float(y @ y)  # uncentred, as usual for a line through the origin
    else:
        xm, ym = float(x.mean()), float(y.mean())
        sxx = float((x - xm) @ (x - xm))
        if sxx == 0:
            raise ValueError("all strains are equal: the slope is undetermined")
        k = float((x - xm) @ (y - ym)) / sxx
        intercept = ym - k * xm
        ss_tot = float((y - ym) @ (y - ym))
    resid = y - (k * x + intercept)
    ss_res = float(resid @ resid)
    s2 = ss_res / dof
    se = math.sqrt(s2 / sxx)
    t = float(stdtrit(dof, 0.5 + confidence / 2))  # Student's t quantile
    r2 = 1.0 - ss_res / ss_tot if ss_tot > 0 else 1.0
    if not all(math.isfinite(v) for v in (k, intercept, se, r2)):
        raise FloatingPointError("non-finite fit")
    return CalibrationFit(
        k_eps=k,
        ci=(k - t * se, k + t * se),
        intercept=intercept,
        r_squared=r2,
        residual_std=math.sqrt(s2),
        n=n,
        confidence=confidence,
        through_origin=through_origin,
    )


def load_pairs_csv(
    path: str | Path,
    columns: tuple[str, str] = ("strain_ue", "shift_pm"),
    scales: tuple[float, float] = (UE, PM),
) -> tuple[np.ndarray, np.ndarray]:
    """Read two columns (``strain_ue``/``shift_pm`` by default; the tip grating's calibration
    reads ``force_mn``/``shift_pm``); returns them as float arrays times ``scales`` (SI).

    ValueError names the file and, where it applies, the line.
    """
    p = Path(path)
    try:
        with p.open(newline="", encoding="utf-8") as fh:
            lines = [ln for ln in fh if ln.strip() and not ln.lstrip().startswith("#")]
    except UnicodeDecodeError as exc:
        raise ValueError(
            f"{p}: not a text (UTF-8) file: {exc.reason} at byte {exc.start}"
        ) from None
    except OSError as exc:
        raise ValueError(f"{p}: cannot read: {exc.strerror or exc}") from None
    try:
        rows = list(csv.reader(lines))
    except csv.Error as exc:  # a NUL byte, an unterminated quote at the end
        raise ValueError(f"{p}: not a CSV file: {exc}") from None
    if not rows:
        raise ValueError(f"{p}: empty file")
    head = [h.strip() for h in rows[0]]
    missing = [c for c in columns if c not in head]
    if missing:
        raise ValueError(f"{p}: header lacks column(s) {missing}; found {head}")
    i_s, i_w = head.index(columns[0]), head.index(columns[1])
    strain, shift = [], []
    for line, row in enumerate(rows[1:], start=2):
        try:
            strain.append(float(row[i_s]))
            shift.append(float(row[i_w]))
        except (IndexError, ValueError) as exc:
            raise ValueError(f"{p}: data row {line}: {exc}") from None
    return np.asarray(strain) * scales[0], np.asarray(shift) * scales[1]


def csv_columns(path: str | Path) -> list[str]:
    """The header of a calibration CSV (the first line that is not a comment), [] if none."""
    try:
        with Path(path).open(newline="", encoding="utf-8") as fh:
            for line in fh:
                if line.strip() and not line.lstrip().startswith("#"):
                    return [h.strip() for h in next(csv.reader([line]))]
    except (OSError, UnicodeDecodeError, csv.Error):
        return []
    return []
