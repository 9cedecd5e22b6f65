"""What a simulated trial ends with: its outcome, and the estimate from what the estimator is told.

The estimator is told the sample as the operator believes it (the scene's ``assumed:``, else
the sample's own values), the rig's calibrated compliance, the campaign's limits and the
misalignment the controller knows (probing's measure, else the plan's IK residual); never the
simulator's switches or the world's truth (``estimation.trial.estimate`` runs the estimators).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from palpate.config.sample import SampleConfig
from palpate.config.scene import SceneConfig
from palpate.config.schema import StackConfig
from palpate.estimation.beam.stage import Stage
from palpate.estimation.trial.estimate import EstimatorInputs, TrialEstimate, estimate_trial
from palpate.estimation.trial.inputs import belief_fields
from palpate.robot.probe_result import ProbeResult
from palpate.robot.trial.outcome import Outcome, outcome_fields
from palpate.robot.trial.run import TrialResult
from palpate.robot.trial.setup import sensor_section
from palpate.sim.sample_law import contact_condition
from palpate.simulation.world import TrialGeometry, TrialSpec, trial_sample
from palpate.wire.dynamixel import TICKS_PER_REV


@dataclass
class TrialOutcome(Outcome):
    """A simulated trial's outcome (``robot.trial.outcome.Outcome``) with its campaign context:
    the spec (the world's truth in ``spec.modulus``), the IK residual, the simulated time."""

    spec: TrialSpec
    ik_residual: float
    ticks: int
    sim_time: float
    series: dict[str, list[float]] = field(default_factory=dict)
    misalignment: float = 0.0  # rad, what the estimator was told (probing's, or the IK's)
    true_misalignment: float | None = None  # rad, the world's at the indentation (sim truth)
    true_motion: float | None = None  # m, the surface's breathing range in contact (sim truth)
    probe: ProbeResult | None = None
    probing_time: float = 0.0  # simulated s in the probing step
    # the ids of the attempts before this one, at longer exposed lengths, that buckled unread
    # (campaign.retry_lengths_mm: campaigns/shorter.py)
    tried: tuple[str, ...] = ()

    def as_dict(self) -> dict[str, Any]:
        jf = self.joint
        bow = self.southwell
        return {
            "trial": self.spec.trial_id,
            "sample": self.spec.sample,
            "tube": self.spec.tube.name,
            "orientation": self.spec.orientation,
            "roll_deg": math.degrees(self.spec.roll),
            "exposed_length_mm": self.spec.exposed_length * 1e3,
            "true_kpa": self.spec.modulus / 1e3,
            "reference_kpa": None if self.spec.reference is None else self.spec.reference / 1e3,
            **self.estimate_row(),
            "joint_contact_mm": None if jf is None or jf.contact is None else jf.contact * 1e3,
            "joint_message": "no loading record" if jf is None else jf.message,
            "model_form": None if jf is None else jf.model_form,
            "best_fit": None if jf is None else jf.best,
            "w0_over_l": None if bow is None else bow.w0_over_l,
            "warnings": [] if jf is None else list(jf.warnings),
            "state": self.state,
            "reason": self.reason,
            "ik_residual_deg": math.degrees(self.ik_residual),
            "misalignment_deg": math.degrees(self.misalignment),
            "true_misalignment_deg": _deg(self.true_misalignment),
            # a breathing world's only (sim truth): the surface's range while the tip touched it
            **({} if self.true_motion is None else {"true_motion_mm": self.true_motion * 1e3}),
            "probe": None if self.probe is None else self.probe.summary(),
            "strain_lean": None if self.lean is None else self.lean.as_dict(),
            "probing_s": self.probing_time,
            "sim_time_s": self.sim_time,
            "log": self.log_path,
            **({"tried": list(self.tried)} if self.tried else {}),
        }


def _sigma(probe: ProbeResult | None) -> float | None:
    """The measured normal's 1-sigma angle (rad), None when no normal was measured."""
    if probe is None or not math.isfinite(probe.normal_sigma):
        return None
    return probe.normal_sigma


def _deg(x: float | None) -> float | None:
    return None if x is None else math.degrees(x)


def estimate_sim_trial(
    result: TrialResult, spec: TrialSpec, scene: SceneConfig, stack: StackConfig, geo: TrialGeometry
) -> TrialEstimate:
    inputs = estimator_inputs(spec, scene, stack, geo, misalignment_of(result, geo), result.probe)
    stage = inputs.stage  # one flush translation for both estimates: the tube the IK picked
    return estimate_trial(
        result,
        kind=stage.kind,
        exposed_length=stage.exposed,
        flush_translation=stage.flush,
        stack=stack,
        section=sensor_section(stack),
        poisson=inputs.poisson,
        inputs=inputs,
    )


def trial_stage(spec: TrialSpec, stack: StackConfig, geo: TrialGeometry) -> Stage:
    """The trial's stage as it runs: the bench column, or the tube the inverse kinematics
    picked (``geo.tube``, which may be another than the spec names)."""
    stage = spec.stage
    return stage if stage.tube is None else Stage.on(stack.tube(geo.tube), stage.exposed)


def misalignment_of(result: TrialResult, geo: TrialGeometry) -> float:
    """What the controller knows of the misalignment: probing's measure, else the plan's IK."""
    return geo.residual if result.probe is None else result.probe.misalignment


def outcome_of(
    spec: TrialSpec,
    geo: TrialGeometry,
    result: TrialResult,
    estimate: TrialEstimate,
    log_path: str | None,
    series: dict[str, list[float]],
) -> TrialOutcome:
    return TrialOutcome(
        spec=spec,
        ik_residual=geo.residual,
        ticks=result.ticks,
        sim_time=result.duration,
        series=series,
        **outcome_fields(result, estimate, log_path),
        misalignment=misalignment_of(result, geo),
        probe=result.probe,
        probing_time=result.probing_time,
    )


def believed_tip(sample: SampleConfig) -> str:
    """The tip contact the operator knows of ``sample`` (its own): ``sticking`` where its
    friction sticks in the world (``sim.sample_law.contact_condition``), else frictionless."""
    stick = contact_condition(sample.friction, sample.poisson) == "stick"
    return "sticking" if stick else "frictionless"


def estimator_inputs(
    spec: TrialSpec,
    scene: SceneConfig,
    stack: StackConfig,
    geo: TrialGeometry,
    misalignment: float | None = None,
    probe: ProbeResult | None = None,
) -> EstimatorInputs:
    """What the joint fit is told: the sample as the operator believes it (the scene's
    ``assumed:``, else the sample's own values), the rig's calibrated compliance, the
    campaign's limits; never the simulator's switches."""
    sample = trial_sample(scene, spec)
    c = scene.campaign
    stage = trial_stage(spec, stack, geo)
    compliance, calibrated = stack.compliance(None if stage.tube is None else stage.tube.name)
    belief = belief_fields(
        sample.assumed,
        thickness=sample.thickness,
        bonded=sample.bonded,
        poisson=sample.poisson,
        surface_radius=sample.curvature_radius,
        material=sample.material,
        tip_contact=believed_tip(sample),
    )
    return EstimatorInputs(
        kind=stage.kind,
        exposed_length=stage.exposed,
        flush_translation=stage.flush,
        tip_radius=stack.sensor.tip_radius,
        encoder_resolution=stack.drive.lead / TICKS_PER_REV,
        misalignment=geo.residual if misalignment is None else misalignment,
        compliance=compliance,
        compliance_calibrated=calibrated,
        misalignment_tolerance=math.radians(c.misalignment_tolerance_deg),
        motion_tolerance=c.motion_tolerance,
        gated=c.gated,
        travel_window=c.max_travel_past_contact,
        designed_range=stack.sensor.designed_range,
        rigid=sample.rigid,
        orientation_verified=probe is None or probe.normal is not None,
        misalignment_sigma=_sigma(probe),
        probe_reason=None if probe is None or probe.normal is not None else probe.reason,
        **belief,
    )
