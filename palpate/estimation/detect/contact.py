"""Model-independent contact detection on a loading record (force or strain against advance).

Two classic detectors from indentation and AFM practice; neither assumes a contact law, so they
give the joint fit (``estimation.jointfit``) a first guess of the contact position and a place
to centre its search:

- ``baseline_deviation``: the baseline's mean and noise come from the first samples (noise by the
  median absolute deviation, so a few outliers do not inflate it); contact is the first sample
  that starts a run of ``run`` consecutive samples deviating by more than ``k`` noise units. It
  is late by the depth at which the load reaches ``k`` sigma (for a sphere F ~ delta^1.5, tens
  to hundreds of micrometres on soft samples): a first guess, not the contact point.
- ``ratio_of_variances`` (Gavara, Sci. Rep. 6:21267, 2016): for each sample, the variance of the
  next ``window`` samples over that of the previous ``window``; the flat baseline has a ratio
  near 1, a loading curve a large one, and the ratio peaks where loading begins.

Both take the record in acquisition order (advance increasing) and return a
:class:`ContactGuess` with ``success`` False and a message (never NaN) when there is no contact.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]
MAD_TO_SIGMA = 1.4826  # sigma of a normal distribution per median absolute deviation


@dataclass(frozen=True)
class ContactGuess:
    """Where loading starts in a record.

    Attributes:
        success: False when the record shows no contact (then index and position are None).
        index: sample index of the detected contact.
        position: the advance (m) at that sample.
        method: "baseline" or "variance-ratio".
        baseline_sigma: noise of the baseline in the signal's units.
        message: what was found, or why nothing was.
    """

    success: bool
    index: int | None
    position: float | None
    method: str
    baseline_sigma: float
    message: str


def _record(advance: ArrayLike, signal: ArrayLike, need: int) -> tuple[FloatArray, FloatArray]:
    x = np.asarray(advance, dtype=np.float64)
    y = np.asarray(signal, dtype=np.float64)
    if x.ndim != 1 or x.shape != y.shape:
        raise ValueError(f"advance and signal must be 1-D of one length, got {x.shape}, {y.shape}")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
        raise ValueError("advance and signal must be finite")
    if x.size < need:
        raise ValueError(f"the record has {x.size} samples; the detector needs at least {need}")
    return x, y


def baseline_deviation(
    advance: ArrayLike,
    signal: ArrayLike,
    *,
    baseline_points: int = 30,
    k: float = 5.0,
    run: int = 5,
    direction: int = 1,
) -> ContactGuess:
    """First sample of a run of ``run`` samples beyond ``k`` baseline sigmas (in ``direction``).

    Args:
        advance: (N,) stage positions (m).
        signal: (N,) force (N) or any signal that grows with load (``direction`` -1 if it falls).
        baseline_points: the first samples, taken to be before contact.
        k, run: threshold in noise units and how many samples in a row must pass it.

    Raises:
        ValueError: shapes, non-finite values, N < baseline_points + run, bad k or run.
    """
    if not (k > 0 and run >= 1 and baseline_points >= 3 and direction in (1, -1)):
        raise ValueError("need k > 0, run >= 1, baseline_points >= 3, direction +-1")
    x, y = _record(advance, signal, baseline_points + run)
    base = y[:baseline_points]
    centre = float(np.median(base))
    sigma = MAD_TO_SIGMA * float(np.median(np.abs(base - centre)))
    if sigma == 0.0:
        sigma = float(np.std(base)) or 1e-300
    above = direction * (y - centre) > k * sigma
    above[:baseline_points] = False
    # first index i with above[i:i+run] all True
    counts = np.convolve(above.astype(np.int64), np.ones(run, dtype=np.int64), mode="valid")
    hits = np.nonzero(counts == run)[0]
    if hits.size == 0:
        return ContactGuess(
            False,
            None,
            None,
            "baseline",
            sigma,
            f"no contact: the signal never stays {k:g} sigma ({k * sigma:.3g}) off its baseline "
            f"for {run} samples",
        )
    i = int(hits[0])
    return ContactGuess(True, i, float(x[i]), "baseline", sigma, f"contact at sample {i}")


def ratio_of_variances(
    advance: ArrayLike, signal: ArrayLike, *, window: int = 20, min_ratio: float = 10.0
) -> ContactGuess:
    """Sample maximising var(next ``window``) / var(previous ``window``) (Gavara 2016).

    A peak ratio below ``min_ratio`` means no loading was seen (success False). On pure noise
    the ratio is F(window - 1, window - 1) distributed and its maximum over a record of ~800
    samples reaches about 4 for window 20; a loading curve gives hundreds.
    """
    if not (window >= 3 and min_ratio > 1):
        raise ValueError("need window >= 3 and min_ratio > 1")
    x, y = _record(advance, signal, 2 * window + 1)
    windows = np.lib.stride_tricks.sliding_window_view(y, window)
    var = windows.var(axis=1)  # var[j] = variance of y[j : j + window]
    before = var[: -window - 1]  # ending at i - 1 for i = window .. N - window
    after = var[window + 1 :]  # starting at i + 1
    floor = max(float(np.median(var)) * 1e-6, 1e-300)
    ratio = after / np.maximum(before, floor)
    j = int(np.argmax(ratio))
    best = float(ratio[j])
    sigma = math.sqrt(float(np.median(var[: max(1, window)])))
    if best < min_ratio:
        return ContactGuess(
            False,
            None,
            None,
            "variance-ratio",
            sigma,
            f"no contact: largest variance ratio {best:.3g} < {min_ratio:g}",
        )
    i = j + window
    return ContactGuess(
        True, i, float(x[i]), "variance-ratio", sigma, f"contact at sample {i} (ratio {best:.3g})"
    )


def difference_sigma(forces: ArrayLike, order: int = 1) -> float:
    """The noise of a record (a tip-force record's, N), from its differences of ``order`` (1:
    successive, of variance 2 sigma^2; 2: second, of variance 6 sigma^2, out of which a linear
    rise drops too; C(2n, n) for order n), by their median absolute deviation, so the load's
    own rise and a few outliers do not inflate it; never below 1e-9."""
    f = np.asarray(forces, dtype=np.float64)
    if f.size < order + 2:
        return 1e-9
    d = np.diff(f, n=order)
    mad = float(np.median(np.abs(d - np.median(d))))
    return max(MAD_TO_SIGMA * mad / math.sqrt(math.comb(2 * order, order)), 1e-9)
