"""The estimates of one finished trial (trial and replay alike): the paper's and the joint fit.

The paper's estimate (:func:`estimate_from_marks`) takes delta from the encoder marks at contact
and at buckling (Eq. 14), the load from the elastica fitted to the strains at buckling (Eq. 7)
and E from Hertz (Eq. 13). The joint fit (:func:`joint_estimate`) is contact-point-free: it
reads the whole loading record. :func:`estimate_trial` runs both on a trial's result; the
simulator and the bench call it, ``palpate replay`` the two functions on a log.

A trial's record is one row per control tick: state, stage advance (encoder, m) and grating
strains. The joint fit uses the loading rows (approach to the end of the post-buckling travel):
``estimation.beamstate`` turns each row's strains into the axial load and the beam's end
shortening, ``estimation.detect_contact`` gives a model-independent first guess of the contact,
and ``estimation.jointfit`` fits the modulus and the contact position together. It never uses
the contact event: a late or early event cannot bias it.

The strain noise is measured on the record itself (each row's 3-grating fit has one degree of
freedom left; the median of its squared residual gives sigma), so nothing about the simulator's
noise setting leaks in. The strains' zero, taken on a few frames at rest, leaves a load offset
common to the whole record; the joint fit fits it beside E and the contact
(``JointFit.load_offset``). What the estimator is told about the sample (thickness, bonding, Poisson
ratio) is written to the log header under ``"estimator"`` so ``palpate replay`` re-runs it with
the same inputs and reproduces the fit bit for bit.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterable, Sequence
from dataclasses import asdict, dataclass
from statistics import NormalDist
from typing import Any

import numpy as np
from numpy.typing import NDArray

from config.schema import SensorConfig, StackConfig
from estimation.beam import Beam
from estimation.beamstate import infer_states
from estimation.corrections import ContactLaw
from estimation.detect_contact import baseline_deviation
from estimation.jointfit import MIN_POINTS, JointFit, joint_fit
from estimation.section import Section
from estimation.stiffness import StiffnessEstimate, paper_estimate
from robot.trial.run import TrialResult
from sensor.strain import grating_intervals

FloatArray = NDArray[np.float64]
LOADING_STATES = frozenset({"approach", "contact", "indenting", "buckled"})
_UNIT_SIGMA = 1e-6  # infer_states is linear in sigma: run at 1e-6, rescale by the measured one


@dataclass(frozen=True)
class EstimatorInputs:
    """What the joint fit is told besides the record (all SI).

    Attributes:
        kind: "bench" (exposed length fixed) or "robot" (L = advance - flush translation).
        exposed_length: L on the bench (m); flush_translation: the tube's, on the robot (m).
        tip_radius, poisson: the tip and the sample's Poisson ratio.
        thickness: sample layer thickness (m) on a rigid substrate, None for a half-space.
        bonded: the layer is glued to its substrate.
        encoder_resolution: stage advance per encoder count (m).
        misalignment: angle between the sensor axis and the surface normal (rad), the IK residual.
    """

    kind: str
    exposed_length: float
    flush_translation: float
    tip_radius: float
    poisson: float
    thickness: float | None
    bonded: bool
    encoder_resolution: float
    misalignment: float

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> EstimatorInputs:
        return cls(**d)

    def law(self) -> ContactLaw:
        return ContactLaw(self.tip_radius, self.poisson, self.thickness, self.bonded, True)


def loading_rows(
    rows: Iterable[tuple[str, float, Sequence[float]]], gratings: int
) -> tuple[FloatArray, FloatArray]:
    """(advance (N,), strains (N, G)) of the loading rows (state, advance, strains) in order."""
    adv: list[float] = []
    eps: list[Sequence[float]] = []
    for state, advance, strains in rows:
        if state in LOADING_STATES and len(strains) == gratings:
            adv.append(advance)
            eps.append(strains)
    return np.asarray(adv, dtype=np.float64), np.asarray(eps, dtype=np.float64).reshape(
        -1, gratings
    )


def strain_sigma(residual: FloatArray, gratings: int) -> float:
    """Per-grating strain noise from per-row rms residuals of the 2-parameter fit (median-based,
    so a few rows the model misses do not inflate it)."""
    dof = gratings - 2
    ss = gratings * residual**2  # sum of squares per row ~ sigma^2 chi2(dof)
    # chi2(1)'s median is exact through the normal; Wilson-Hilferty (< 1 % off) above
    median = NormalDist().inv_cdf(0.75) ** 2 if dof == 1 else dof * (1 - 2 / (9 * dof)) ** 3
    return max(math.sqrt(float(np.median(ss)) / median), 1e-9)


def joint_estimate(
    advance: FloatArray,
    strains: FloatArray,
    inputs: EstimatorInputs,
    sensor: SensorConfig,
    section: Section,
) -> JointFit:
    """The joint fit of one trial's loading record (see the module docstring)."""
    law = inputs.law()
    n, gratings = strains.shape
    if n < MIN_POINTS:
        return JointFit(False, f"too few points: {n} loading samples, the fit needs {MIN_POINTS}")
    if inputs.kind == "robot":
        lengths = advance - inputs.flush_translation
    else:
        lengths = np.full(n, inputs.exposed_length)
    intervals = grating_intervals(sensor, 0.0)[None, :, :] + lengths[:, None, None]
    states = infer_states(
        strains, intervals, lengths, section.EA, section.fiber_offset, _UNIT_SIGMA
    )
    k = strain_sigma(states.residual, gratings) / _UNIT_SIGMA
    guess = baseline_deviation(advance, states.P, baseline_points=min(30, n // 4))
    if not guess.success:
        return JointFit(False, guess.message, n_points=n, law=law.name)
    return joint_fit(
        advance,
        states.P,
        states.e,
        law,
        sigma_force=k * states.sigma_P,
        sigma_shortening=k * states.sigma_e,
        encoder_resolution=inputs.encoder_resolution,
        contact_guess=guess.position,
        misalignment=inputs.misalignment,
    )


def joint_from_rows(
    rows: Iterable[tuple[str, float, Sequence[float]]],
    inputs: EstimatorInputs,
    stack: StackConfig,
    section: Section,
) -> JointFit:
    """The joint fit from (state, advance, strains) rows: the trial's record or a log's samples."""
    advance, strains = loading_rows(rows, len(stack.sensor.used_gratings))
    return joint_estimate(advance, strains, inputs, stack.sensor, section)


def exposed_length_at(kind: str, x: float, fixed_length: float, flush_translation: float) -> float:
    """Exposed length (m) at stage position ``x``: fixed on the bench, on the robot the stage
    translation past the tube's flush translation. Shared by the trial and ``palpate replay``."""
    if kind == "bench":
        return fixed_length
    return x - flush_translation


def estimate_from_marks(
    x_contact: float | None,
    x_buckling: float | None,
    strains: tuple[float, ...],
    length: float | None,
    stack: StackConfig,
    section: Section,
    poisson: float,
) -> StiffnessEstimate | None:
    """The paper's estimate: delta from the encoder (Eq. 14), P from the FBG-fitted elastica at
    the exposed length at buckling (Eq. 7; P_cr when the fit fails), E from Hertz (Eq. 13)."""
    if x_contact is None or x_buckling is None or length is None:
        return None
    beam = Beam.from_section(section, length)
    P: float | None = None
    if strains:
        fit = beam.fit_strains(np.asarray(strains), grating_intervals(stack.sensor, length))
        if fit.success and fit.P > 0:
            P = float(fit.P)
    return paper_estimate(
        x_contact, x_buckling, length, section, stack.sensor.tip_radius, poisson, P=P
    )


@dataclass(frozen=True)
class TrialEstimate:
    """What :func:`estimate_trial` found.

    Attributes:
        paper: the paper's estimate (Eqs. 13-14), None when no buckling was detected.
        exposed_length_at_buckling: L (m) at the buckling mark, None without one.
        joint: the joint fit, None when the runner did not ask for it.
        joint_seconds: wall time of the joint fit (for reports, never for tests).
    """

    paper: StiffnessEstimate | None
    exposed_length_at_buckling: float | None
    joint: JointFit | None = None
    joint_seconds: float | None = None


def estimate_trial(
    result: TrialResult,
    *,
    kind: str,
    exposed_length: float,
    flush_translation: float,
    stack: StackConfig,
    section: Section,
    poisson: float,
    inputs: EstimatorInputs | None = None,
) -> TrialEstimate:
    """The estimates of a finished trial: the paper's from its marks at the exposed length at
    buckling (:func:`exposed_length_at` of ``kind``, ``exposed_length`` and
    ``flush_translation``, m), and with ``inputs`` the joint fit of its record."""
    m = result.marks
    paper: StiffnessEstimate | None = None
    length: float | None = None
    if m.x_buckling is not None:
        length = exposed_length_at(kind, m.x_buckling, exposed_length, flush_translation)
        paper = estimate_from_marks(
            m.x_contact, m.x_buckling, m.strains_at_buckling, length, stack, section, poisson
        )
    if inputs is None:
        return TrialEstimate(paper, length)
    start = time.perf_counter()
    joint = joint_from_rows(result.record, inputs, stack, section)
    return TrialEstimate(paper, length, joint, time.perf_counter() - start)
