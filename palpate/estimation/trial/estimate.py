"""The estimates of one finished trial (trial and replay alike): the paper's and the joint fit.

The paper's estimate (:func:`estimate_from_marks`) takes delta from the encoder marks at contact
and at buckling (Eq. 14), the load from the elastica fitted to the strains at buckling (Eq. 7)
and E from Hertz (Eq. 13). The joint fit (:func:`joint_estimate`) is contact-point-free: it
reads the whole loading record. :func:`estimate_trial` runs both on a trial's result; the
simulator and the bench call it, ``palpate replay`` the two functions on a log.

A trial's record is one row per control tick: state, stage advance (encoder, m) and grating
strains. The joint fit uses the loading rows (approach to the end of the post-buckling travel):
``estimation.beam.states`` turns each row's strains into the axial load and the beam's end
shortening, ``estimation.detect.contact`` gives a model-independent first guess of the contact,
and ``estimation.jointfit`` fits the modulus and the contact position together. It never uses
the contact event: a late or early event cannot bias it.

The strain noise is measured on the record itself (each row's 3-grating fit has one degree of
freedom left; the median of its squared residual gives sigma). The strains' zero leaves a load
offset common to the record, fitted beside E and the contact (``JointFit.load_offset``). What
the estimator is told about the sample is written to the log header under ``"estimator"`` so
``palpate replay`` re-runs it with the same inputs and reproduces the fit bit for bit.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ...config.schema import SensorConfig, StackConfig
from ..beam.elastica.constants import P_CRIT
from ..beam.model import Beam
from ..beam.section import Section, grating_intervals
from ..beam.stage import Stage
from ..beam.states import BeamStates
from ..detect.contact import baseline_deviation, difference_sigma
from ..fits.compliance import ComplianceFit, fit_compliance, less
from ..fits.southwell import SouthwellFit, southwell
from ..fits.stiffness import StiffnessEstimate, paper_estimate
from ..fits.strain_fit import fit_strains
from ..jointfit import MIN_POINTS, JointFit, joint_fit
from ..pose.heartbeat import Heartbeat
from ..pose.misalignment import Lean
from ..pose.motion import Motion
from ..relaxation import RelaxationFit
from ..verdict import TrialFacts, Verdict, judge, relaxed_verdict
from .finished import FinishedTrial, tip_load_at_buckling
from .inputs import EstimatorInputs
from .lean import lean_of_rows, loading_tip, rows_in
from .motion import Row, measured_heart, motion_envelope, steady_rows, unfixed
from .relaxed import relaxation_of
from .states import (
    LOADING_STATES,
    WAITING,
    RowLoads,
    last_attempt,
    on_beam,
    record_lengths,
    row_loads,
    states_at,
)
from .strobe import strobe_fit, strobed_rows

__all__ = [
    "EstimatorInputs",
    "RecordEstimate",
    "TrialEstimate",
    "estimate_from_marks",
    "estimate_trial",
    "exposed_length_at",
    "fit_record",
    "fit_rows",
    "loading_rows",
    "tip_load_at_buckling",
    "verdict_for",
]

FloatArray = NDArray[np.float64]


def loading_rows(
    rows: Iterable[tuple[str, float, Sequence[float]]], gratings: int
) -> tuple[FloatArray, FloatArray]:
    """(advance (N,), strains (N, G)) of the loading rows (state, advance, strains) in order."""
    return rows_in(rows, LOADING_STATES, gratings)


@dataclass(frozen=True)
class RecordEstimate:
    """What the record gives: the joint fit and the Southwell fit of the beam's bow (None when
    the record is too short for either); on a rigid reference, the compliance instead.
    ``tip_load``: the fits read the load from a tip grating; ``motion``: the surface's along
    the axis, measured from it, and the heart's ``heart`` (``estimation.trial.motion``)."""

    joint: JointFit | None
    southwell: SouthwellFit | None = None
    calibration: ComplianceFit | None = None
    lean: Lean | None = None
    relaxation: RelaxationFit | None = None
    tip_load: bool = False
    loads: RowLoads = dataclasses.field(default_factory=dict)  # the beam states' P, by row
    motion: Motion | None = None
    heart: Heartbeat | None = None

    @property
    def tip_bow(self) -> float | None:
        """The bow w0/L fitted against a tip grating's load, None without one (a bow fitted
        against the strains' own load is not independent of them)."""
        bow = self.southwell
        if not self.tip_load or bow is None or not bow.success:
            return None
        return bow.w0_over_l


def fit_record(
    advance: FloatArray,
    strains: FloatArray,
    inputs: EstimatorInputs,
    sensor: SensorConfig,
    section: Section,
    tip_forces: FloatArray | None = None,
) -> RecordEstimate:
    """The joint fit of one trial's loading record (see the module docstring), and the beam's
    bow from its pre-buckling part (``estimation.fits.southwell``). With ``tip_forces`` (N, one per
    row, from a tip force grating) the fit reads the load from them instead of the beam's axial
    strain, with their noise measured on the record
    (``estimation.detect.contact.difference_sigma``). Rows whose exposed length leaves a
    grating off the beam (an advance taken against a drift estimated far beyond the record's)
    have no beam state and are left out."""
    lengths = record_lengths(advance, inputs)
    keep = on_beam(lengths, sensor)
    if not keep.all():
        advance, strains, lengths = advance[keep], strains[keep], lengths[keep]
        tip_forces = None if tip_forces is None else tip_forces[keep]
    n = strains.shape[0]
    if n < MIN_POINTS:
        msg = f"too few points: {n} loading samples, the fit needs {MIN_POINTS}"
        if inputs.rigid:
            return RecordEstimate(None, calibration=ComplianceFit(False, msg, n_points=n))
        return RecordEstimate(JointFit(False, msg, n_points=n, law=inputs.law().name))
    states, k = states_at(strains, lengths, sensor, section)
    if inputs.rigid:  # the tube's (stage's) compliance: a tip grating's element is the sensor's
        element = 0.0 if sensor.tip_grating is None else sensor.tip_grating.compliance
        fit = less(fit_compliance(advance, states.P, states.e), element)
        return RecordEstimate(None, calibration=fit, loads=row_loads(advance, strains, states))
    force, sigma_force = states.P, k * states.sigma_P
    if tip_forces is not None:
        force, sigma_force = tip_forces, np.full(n, difference_sigma(tip_forces))
    guess = baseline_deviation(advance, force, baseline_points=min(30, n // 4))
    joint = joint_fit(
        advance,
        force,
        states.e,
        inputs.belief(),
        sigma_force=sigma_force,
        sigma_shortening=k * states.sigma_e,
        encoder_resolution=inputs.encoder_resolution,
        contact_guess=guess.position if guess.success else None,
        misalignment=inputs.misalignment,
    )
    # the bow against the load the fit read: the tip grating's, independent of the strains
    bow = _bow(force, states, lengths, section)
    loads = row_loads(advance, strains, states)
    return RecordEstimate(joint, bow, tip_load=tip_forces is not None, loads=loads)


def critical_load(section: Section, length: float) -> float:
    """P_cr = 20.19 EI / L^2 (N) of the clamped-pinned sensor at exposed length L (m)."""
    return float(P_CRIT * section.EI / length**2)


def _bow(
    load: FloatArray, states: BeamStates, lengths: FloatArray, section: Section
) -> SouthwellFit:
    """The Southwell fit of ``load`` (the strains' or a tip grating's, N) against the bending
    amplitude, at the exposed length of the record's largest load."""
    length = float(lengths[int(np.argmax(load))])
    if length <= 0:
        return SouthwellFit(False, "no exposed length at the largest load")
    return southwell(load, states.z, length, critical_load(section, length))


def fit_rows(
    rows: Iterable[tuple[str, float, Sequence[float]]],
    inputs: EstimatorInputs,
    stack: StackConfig,
    section: Section,
    times: Sequence[float] | None = None,
    tip_forces: Sequence[float | None] | None = None,
    beats: Sequence[float] | None = None,
) -> RecordEstimate:
    """The estimates from (state, advance, strains) rows: the trial's record or a log's samples;
    beside them the load's lean from the rows before buckling (``estimation.trial.lean``) and, with
    each row's time (s) and a hold in the rows, the relaxation (``estimation.trial.relaxed``). With
    each row's tip-grating load (N), the joint fit reads the load from it; with the ticks (s)
    of an ECG's R-wave pulses, in a gated trial (``inputs.gated``; for an older log, rows that
    wait for a breath hold), the record is read in the heart's quiet phase
    (``estimation.trial.strobe``) or the beat taken out (``estimation.trial.motion``)."""
    rows = list(rows)
    held = inputs.gated if inputs.gated is not None else any(r[0] == WAITING for r in rows)
    beats = beats if held else None  # in a breath hold only (a trial may arrive in one)
    rows, times, tip_forces = last_attempt(rows, times, tip_forces)  # of a gated trial
    gratings = len(stack.sensor.used_gratings)

    def fit(rows: list[Row]) -> RecordEstimate:
        advance, strains = loading_rows(rows, gratings)
        tip = loading_tip(rows, tip_forces, gratings)
        return fit_record(advance, strains, inputs, stack.sensor, section, tip)

    def joint(rows: list[Row]) -> JointFit | None:
        return fit(rows).joint

    drift = inputs.motion_tolerance is not None  # taken out where the campaign expects it
    heart = measured_heart(rows, times, tip_forces, beats, drift, joint)
    quiet = strobed_rows(rows, times, tip_forces, beats)
    if quiet is not None and times is not None:
        fitted, (read, motion) = fit(rows), strobe_fit(quiet, times, drift, joint)
    else:
        rows, motion = steady_rows(raw := rows, times, tip_forces, heart, drift)
        fitted = fit(rows)
        env = motion_envelope(fitted.joint, raw, times, tip_forces, (motion, heart), drift, joint)
        read = unfixed(env, heart, beating=bool(beats))
    fitted = dataclasses.replace(fitted, joint=read, motion=motion, heart=heart)
    if inputs.rigid:
        return fitted
    lean = lean_of_rows(rows, stack.sensor, section, inputs)
    relaxation = None
    if times is not None:
        relaxation = relaxation_of(
            rows, times, inputs, stack.sensor, section, fitted.joint, tip_forces
        )
    return dataclasses.replace(fitted, lean=lean, relaxation=relaxation)


def verdict_for(
    fitted: RecordEstimate,
    inputs: EstimatorInputs,
    state: str,
    reason: str,
    section: Section,
    buckling_tip_load: float | None = None,
) -> tuple[Verdict, Verdict | None]:
    """The trial's verdicts (``estimation.verdict``) from what its record gave (the joint fit,
    the lean, the relaxation, the bow, the surface's motion and the heart's beat), its inputs
    and how it ended: on the elastic estimate, and on the relaxed modulus when the trial held
    (else None). ``buckling_tip_load``: the tip grating's load at the buckling mark (N)."""
    joint, relaxation, motion = fitted.joint, fitted.relaxation, fitted.motion
    length = inputs.exposed_length
    if joint is not None and joint.contact is not None:
        length = inputs.stage.exposed_length(joint.contact)
    facts = TrialFacts(
        state=state,
        reason=reason,
        travel_window=inputs.travel_window,
        critical_load=critical_load(section, length) if length > 0 else None,
        misalignment=inputs.misalignment,
        misalignment_tolerance=inputs.misalignment_tolerance,
        compliance_calibrated=inputs.compliance_calibrated,
        poisson=inputs.poisson,
        compliance_max=inputs.compliance[1],
        orientation_verified=inputs.orientation_verified,
        lean=fitted.lean,
        misalignment_sigma=inputs.misalignment_sigma,
        relaxation=relaxation,
        designed_range=inputs.designed_range,
        probe_reason=inputs.probe_reason,
        buckling_tip_load=buckling_tip_load,
        bow=fitted.tip_bow,
        motion=None if motion is None else motion.moved,
        motion_tolerance=inputs.motion_tolerance,
        heart=fitted.heart,
    )
    elastic = judge(joint, facts, inputs.contact_radius)
    return elastic, relaxed_verdict(relaxation, elastic, facts)


def exposed_length_at(kind: str, x: float, fixed_length: float, flush_translation: float) -> float:
    """Exposed length (m) at stage position ``x``: fixed on the bench, on the robot the stage
    translation past the tube's flush translation. Shared by the trial and ``palpate replay``."""
    return Stage.of(kind, fixed_length, flush_translation).exposed_length(x)


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
        fit = fit_strains(beam, np.asarray(strains), grating_intervals(stack.sensor, length))
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
        southwell: the beam's bow fitted from the record (None without a joint fit).
        verdict: ok, suspect or none, with reasons (None without a joint fit).
        calibration: the rig's compliance, on a rigid reference (instead of the joint fit).
        relaxation: the relaxed and instantaneous moduli, when the trial held (else None).
        relaxed_verdict: the verdict on the relaxed modulus, when the trial held.
        beam_loads: the axial load the joint fit's beam states gave each loading row, by row
            (``estimation.trial.states.RowLoads``): the recording's tip force reuses them.
        motion: the surface's motion along the axis between the first touch and the release
            (m, :func:`record_motion`), None without a tip grating; ``heart``: the heart's beat
            taken out of the record, peak to peak (m), None without an ECG's R waves.
    """

    paper: StiffnessEstimate | None
    exposed_length_at_buckling: float | None
    joint: JointFit | None = None
    joint_seconds: float | None = None
    southwell: SouthwellFit | None = None
    verdict: Verdict | None = None
    calibration: ComplianceFit | None = None
    lean: Lean | None = None
    relaxation: RelaxationFit | None = None
    relaxed_verdict: Verdict | None = None
    beam_loads: RowLoads = dataclasses.field(default_factory=dict)
    motion: float | None = None
    heart: float | None = None


def estimate_trial(
    result: FinishedTrial,
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
    fitted = fit_rows(
        result.record, inputs, stack, section, result.times, result.tip_forces, result.beats
    )
    seconds = time.perf_counter() - start
    verdict, relaxed = None, None
    motion = fitted.motion
    if not inputs.rigid:
        verdict, relaxed = verdict_for(
            fitted,
            inputs,
            result.state.value,
            result.reason,
            section,
            tip_load_at_buckling(result.record, result.tip_forces),
        )
    return TrialEstimate(
        paper,
        length,
        fitted.joint,
        seconds,
        fitted.southwell,
        verdict,
        fitted.calibration,
        fitted.lean,
        fitted.relaxation,
        relaxed,
        fitted.loads,
        None if motion is None else motion.moved,
        None if fitted.heart is None else 2.0 * fitted.heart.amplitude,
    )
