"""The paper's stiffness estimator (Eqs. 13-14) and the statistics of Tables I and II.

``paper_estimate`` turns the two encoder readings of a trial into a Young's modulus:

- indentation before buckling, Eq. 14: ``delta = X_buckling - X_contact``;
- the axial load at that moment from the beam model: by default the fixed-pinned Euler load
  ``P_cr = 20.19 EI / L^2`` at the exposed length at buckling (the paper's choice: the beam has
  just started to buckle), or a load the caller got elsewhere (e.g. an FBG fit of the beam state);
- the Hertz sphere, Eq. 13: ``E = 3/4 P (1 - nu^2) / sqrt(delta^3 R_tip)``.

``summarize`` gives one sample's row of Table I: mean estimate, RMSE against the modulus judged
against (the true one in simulation, the reference measurement on the bench), IQR, relative error,
count, after dropping estimates above 3 MPa as the paper did.

Pure functions on floats; all moduli in Pa, lengths in m, forces in N.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from ..beam.section import P_CRIT, euler_load
from ..contact.hertz import hertz_modulus

EULER_FIXED_PINNED = P_CRIT  # kept as a name the tests and callers use
"""p_cr = P_cr L^2 / EI = mu^2 with tan(mu) = mu: 20.1907 (fixed-pinned column)."""

PAPER_OUTLIER_ABOVE = 3e6
"""The paper dropped estimates above 3 MPa (Section IV-A)."""


class HasFlexuralRigidity(Protocol):
    """Anything with an ``EI`` (N m^2), e.g. ``estimation.beam.section.Section``."""

    @property
    def EI(self) -> float: ...


@dataclass(frozen=True)
class StiffnessEstimate:
    """One trial's estimate.

    Attributes:
        success: False when the trial gives no estimate (``modulus`` is then None).
        modulus: E in Pa, or None.
        delta: indentation X_b - X_c in m (may be <= 0 on failure).
        force: the axial load P used, N.
        message: why it failed, or "ok".
    """

    success: bool
    modulus: float | None
    delta: float
    force: float
    message: str


def paper_estimate(
    x_contact: float,
    x_buckling: float,
    exposed_length_at_buckling: float,
    section: float | HasFlexuralRigidity,
    tip_radius: float,
    poisson: float,
    P: float | None = None,
) -> StiffnessEstimate:
    """The paper's estimate from the encoder at contact and at buckling (Eqs. 13-14).

    Args:
        x_contact: stage position at contact (m).
        x_buckling: stage position when buckling was detected (m).
        exposed_length_at_buckling: exposed length L (m) at that moment.
        section: EI (N m^2) or an object with an ``EI`` attribute.
        tip_radius: R_tip (m).
        poisson: the tissue's Poisson ratio (known, per the paper).
        P: axial load (N) to use instead of P_cr(L).

    Returns:
        A :class:`StiffnessEstimate`; ``success`` False (with the reason) when ``delta <= 0``,
        i.e. buckling was detected at or before contact.

    Raises:
        ValueError: non-finite encoder values, or non-physical L, EI, R_tip, nu or P.
    """
    if not (math.isfinite(x_contact) and math.isfinite(x_buckling)):
        raise ValueError(f"encoder positions must be finite; got {x_contact}, {x_buckling}")
    EI = section if isinstance(section, int | float) else float(section.EI)
    if not tip_radius > 0:
        raise ValueError(f"tip_radius must be > 0, got {tip_radius}")
    _check_poisson(poisson)
    force = _axial_load(EI, exposed_length_at_buckling, P)
    delta = x_buckling - x_contact
    if not delta > 0:
        return StiffnessEstimate(
            success=False,
            modulus=None,
            delta=delta,
            force=force,
            message=(
                f"no indentation before buckling: X_b - X_c = {delta:.3e} m <= 0 "
                "(contact detected late, or the tissue is stiffer than the method resolves)"
            ),
        )
    return StiffnessEstimate(
        success=True,
        modulus=float(hertz_modulus(force, delta, tip_radius, poisson)),
        delta=delta,
        force=force,
        message="ok",
    )


@dataclass(frozen=True)
class SampleSummary:
    """One sample's statistics (a row of Tables I/II), in Pa; None where no estimate is left.

    Attributes:
        against: the modulus the estimates are judged against: the world's true modulus in
            simulation, a sample's reference measurement on the bench.
        mean: mean of the kept estimates.
        median: median of the kept estimates.
        rmse: sqrt(mean((E_i - against)^2)) over the kept estimates.
        iqr: 75th - 25th percentile (numpy's linear interpolation) of the kept estimates.
        relative_error: (mean - against) / against.
        count: estimates kept.
        outliers: estimates dropped by the outlier rule.
        failed: estimates that were missing (None, NaN or a failed StiffnessEstimate).
    """

    against: float
    mean: float | None
    median: float | None
    rmse: float | None
    iqr: float | None
    relative_error: float | None
    count: int
    outliers: int
    failed: int


def summarize(
    estimates: Iterable[float | StiffnessEstimate | None],
    against: float,
    outlier_above: float | None = PAPER_OUTLIER_ABOVE,
) -> SampleSummary:
    """Mean, RMSE against ``against``, IQR and counts of one sample's estimates.

    Args:
        estimates: moduli in Pa, StiffnessEstimate results, or None for a failed trial.
        against: what the estimates are judged against (Pa, > 0): the true modulus in
            simulation, the sample's reference measurement on the bench.
        outlier_above: estimates strictly above this (Pa) are dropped, as in the paper;
            None keeps everything.

    Raises:
        ValueError: ``against`` not positive and finite.
    """
    if not (math.isfinite(against) and against > 0):
        raise ValueError(f"the modulus judged against must be > 0 and finite, got {against}")
    values: list[float] = []
    failed = 0
    for item in estimates:
        value = item.modulus if isinstance(item, StiffnessEstimate) else item
        if value is None or not math.isfinite(value):
            failed += 1
        else:
            values.append(float(value))
    arr = np.asarray(values, dtype=np.float64)
    keep = arr if outlier_above is None else arr[arr <= outlier_above]
    outliers = int(arr.size - keep.size)
    if keep.size == 0:
        return SampleSummary(against, None, None, None, None, None, 0, outliers, failed)
    mean = float(np.mean(keep))
    q75, q25 = np.percentile(keep, [75.0, 25.0])
    return SampleSummary(
        against=against,
        mean=mean,
        median=float(np.median(keep)),
        rmse=float(np.sqrt(np.mean((keep - against) ** 2))),
        iqr=float(q75 - q25),
        relative_error=(mean - against) / against,
        count=int(keep.size),
        outliers=outliers,
        failed=failed,
    )


def _axial_load(EI: float, length: float, P: float | None) -> float:
    """The load (N) the estimate uses: ``P`` when given, else P_cr = 20.19 EI / L^2 at the
    exposed length ``length`` (m); EI and L are checked either way."""
    if not (math.isfinite(length) and length > 0):
        raise ValueError(f"exposed_length_at_buckling must be > 0 m, got {length}")
    force = euler_load(EI, length)  # also validates EI
    if P is not None:
        if not (math.isfinite(P) and P > 0):
            raise ValueError(f"P must be a positive finite load in N, got {P}")
        force = float(P)
    return force


def _check_poisson(poisson: float) -> None:
    if not 0.0 <= poisson <= 0.5:
        raise ValueError(f"poisson must be in [0, 0.5], got {poisson}")
