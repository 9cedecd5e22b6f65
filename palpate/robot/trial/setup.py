"""What every trial runner builds the same way from a campaign: the sensor's section, guards, rig
settings, the stage's position tolerance, the buckling detector and the trial plan.

One place for the simulated campaign (``palpate.simulation.trial``), the bench
(``palpate.lab.trial``) and teleoperation (``palpate teleop``), so a guard, a threshold or a speed
means the same everywhere.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from ...config.scene import CampaignConfig
from ...config.schema import MM, StackConfig, TubeConfig
from ...estimation.beam.elastica.constants import P_CRIT
from ...estimation.beam.section import Section, grating_intervals
from ...estimation.beam.section import sensor_section as section_of
from ...estimation.beam.states import infer_states, onset_mode
from ...estimation.detect.buckling import BucklingDetector, CusumDetector, NormThreshold
from ...estimation.detect.plateau import LoadPlateau
from ...sensor.strain import StrainChain
from ...wire.dynamixel import TICKS_PER_REV
from ..indentation import STATE_TIMEOUT, Guards, Prober, TrialPlan
from ..probing import ProbeGeometry, ProbeRoutine, ProbeSettings, probe_budget
from ..rig import RigSettings

FloatArray = NDArray[np.float64]


def sensor_section(stack: StackConfig) -> Section:
    """The sensor's composite section (EI, EA, fiber offset) from the robot configuration."""
    return section_of(stack.sensor)


PROBE_SEARCH = 6e-3  # m the first touch looks past the approach window (samples 1-5 mm off)
BUDGET_SHARE = 0.8  # probing's budget never exceeds this share of the state timeout
TIP_TOUCH_SHARE = 0.1  # with a tip grating a touch is this share of P_cr (the paper's
# sensor touches at 25 ue of axial strain, 18 % of its P_cr; a seek stops at twice it)
SETTLE_ALLOWANCE = 0.4  # s per touch at rest for the strain zero (10 ticks at 25 Hz or more)


def guards_for(campaign: CampaignConfig, stack: StackConfig, tick: float) -> Guards:
    """The trial guards of a campaign: travel past contact, fiber strain, the stream's stale
    timeout (at least five control periods ``tick``, s) and its lost timeout (at least that)."""
    stale = max(stack.board.stale_timeout_s, 5 * tick)
    return Guards(
        max_travel_past_contact=campaign.max_travel_past_contact_mm * MM,
        strain_limit=stack.fbg.strain_limit,
        stream_timeout=stale,
        stream_lost=max(stack.board.lost_timeout_s, stale),
        max_twist=stack.drive.max_twist,
    )


PROBE_SPEED = 2.5e-3  # m/s, a touch's approach


def probe_offsets(points: int, step: float) -> tuple[float, ...]:
    """The rolls of the touches after the first, relative to the plan's (rad): a small step to
    one side first (the surface's slope, before a wide move: until then the surface may be
    anywhere within the search's tilt), then the full ``step`` on that side (predicted from
    the slope), then on the other (predicted from a plane), then between. Three touches span
    one side and a quarter: four are needed for a normal to a fraction of a degree."""
    pattern = (0.25, 1.0, -1.0, -0.5, 0.5, -0.75, 0.75, -0.25)
    return tuple(step * k for k in pattern[: points - 1])


def prober_for(
    campaign: CampaignConfig,
    stack: StackConfig,
    tube: TubeConfig,
    surface_radius: tuple[float, float] | None = None,
) -> Callable[[TrialPlan], Prober] | None:
    """The probing step of a campaign's trials with ``tube`` (``robot.probing``), None when
    the campaign does not probe. Touches are approached at ``PROBE_SPEED``: the stage stops
    v^2 / 2a past the touch (0.06 mm at 2.5 mm/s and 50 mm/s^2, 0.25 mm at 5 mm/s, which on
    a 1 MPa sample is the whole way to buckling); the moves between them at the top speed.
    ``surface_radius``: the convex surface's believed radius (min, max; m), None: flat or
    unknown (``config.sample.AssumedConfig.surface_radius``)."""
    probing = campaign.probing()
    if probing is False:
        return None
    geometry = probe_geometry(stack, tube)

    def build(plan: TrialPlan) -> Prober:
        step = geometry.roll_step(campaign.probe_sagitta_mm * MM, plan.roll, plan.contact_advance)
        settings = ProbeSettings(
            offsets=probe_offsets(campaign.probe_points, step),
            touch_strain=campaign.probe_touch_ue * 1e-6,
            touch_force=tip_touch_force(stack, plan.contact_advance - tube.flush_translation),
            speed=min(PROBE_SPEED, stack.drive.max_speed),
            fast_speed=stack.drive.max_speed,
            decel=stack.drive.max_accel,
            max_residual=math.radians(campaign.misalignment_tolerance_deg),
            max_miss=campaign.miss_tolerance_mm * MM,
            standoff=plan.standoff,
            replan=probing is True,
            search=PROBE_SEARCH,
            surface_radius=surface_radius,
        )
        budget = probe_budget(
            settings.offsets,
            plan.approach_window,
            settings.speed,
            settings.fast_speed,
            stack.drive.max_roll_speed,
            SETTLE_ALLOWANCE,
            settings.search,
        )
        settings = dataclasses.replace(settings, budget=min(budget, BUDGET_SHARE * STATE_TIMEOUT))
        return ProbeRoutine(geometry, settings, plan)

    return build


def probe_geometry(stack: StackConfig, tube: TubeConfig) -> ProbeGeometry:
    """Probing's view of ``tube``: its kinematics, the tip, the drive's limits, the beam's
    bending shape at an exposed length and the loads a record's strains show."""
    section = sensor_section(stack)
    fiber_offset = section.fiber_offset

    def bending(length: float) -> tuple[float, ...]:
        intervals = grating_intervals(stack.sensor, length)
        return tuple(onset_mode(intervals, length, fiber_offset).tolist())

    def loads(advance: FloatArray, strains: FloatArray) -> FloatArray:
        lengths = advance - tube.flush_translation
        intervals = grating_intervals(stack.sensor, 0.0)[None, :, :] + lengths[:, None, None]
        states = infer_states(strains, intervals, lengths, section.EA, fiber_offset, 1e-6)
        return np.asarray(states.P / section.EA)

    return ProbeGeometry(
        tube,
        tip_radius=stack.sensor.tip_radius,
        translation_limits=stack.drive.translation_limits,
        roll_limits=stack.drive.roll_limits,
        bending_mode=bending,
        loads=loads,
    )


def tip_touch_force(stack: StackConfig, length: float) -> float | None:
    """The tip load (N) that is a probing touch for a sensor with a tip grating (its axial
    strain may be at the noise): TIP_TOUCH_SHARE of P_cr at the contact's exposed ``length``
    (m); None without a tip grating."""
    if stack.sensor.tip_grating is None or length <= 0:
        return None
    return TIP_TOUCH_SHARE * P_CRIT * sensor_section(stack).EI / length**2


def rig_settings(
    campaign: CampaignConfig,
    stack: StackConfig,
    tick: float,
    *,
    sync_to_clock: bool = False,
    exposed_length: float | None = None,
) -> RigSettings:
    """The rig's settings for a campaign at a control period ``tick`` (s), the one place a trial
    keeps it. ``sync_to_clock`` only for emulators on a virtual clock. With ``exposed_length``
    (m) FBG contact reads the axial strain with the beam's onset bow taken out
    (``estimation.beam.states.axial_strain``)."""
    mode = None
    if exposed_length is not None:
        fiber_offset = sensor_section(stack).fiber_offset
        intervals = grating_intervals(stack.sensor, exposed_length)
        mode = tuple(onset_mode(intervals, exposed_length, fiber_offset).tolist())
    return RigSettings(
        tick=tick,
        contact=campaign.contact,
        sync_to_clock=sync_to_clock,
        frame_period=1.0 / stack.board.rate_hz,
        fbg_bending_mode=mode,
        bus_silence=stack.servos.silence,
    )


def position_tolerance(stack: StackConfig) -> float:
    """The stage encoder's resolution, 1.5 ticks of the translation servo (m)."""
    return 1.5 * stack.drive.lead / TICKS_PER_REV


def trial_plan(
    campaign: CampaignConfig, stack: StackConfig, *, roll: float, contact: float, home: float
) -> TrialPlan:
    """The plan of one trial: roll to ``roll`` (rad) at the ``home`` advance (m), advance fast to
    the campaign's stand-off before the expected ``contact`` advance (m), approach and indent at
    the campaign's speeds (the approach at the indentation speed when it ramps through the
    contact), keep indenting ``post_buckling_mm`` after buckling, hold ``hold_s``, retract."""
    return TrialPlan(
        roll=roll,
        contact_advance=contact,
        home_advance=home,
        standoff=campaign.standoff_mm * MM,
        post_buckling_travel=campaign.post_buckling_mm * MM,
        fast_speed=stack.drive.max_speed,
        approach_speed=(
            campaign.indent_speed_mm_per_s
            if campaign.ramp_through_contact
            else campaign.approach_speed_mm_per_s
        )
        * MM,
        indent_speed=campaign.indent_speed_mm_per_s * MM,
        position_tolerance=position_tolerance(stack),
        hold_time=campaign.hold_s,
        gated=campaign.gated,
    )


def detector_for(campaign: CampaignConfig, chain: StrainChain) -> BucklingDetector:
    """The campaign's buckling detector; CUSUM takes its noise from the zeroed baseline (the
    stream's real noise, not a configured figure), the tip grating's plateau from the load's
    own record."""
    if campaign.detector == "paper":
        return NormThreshold(campaign.detector_threshold_ue * 1e-6)
    if campaign.detector == "tip":
        return LoadPlateau()
    sigma = float(np.max(chain.strain_noise()))
    return CusumDetector(sigma=max(sigma, 1e-7))
