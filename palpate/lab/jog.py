"""A jog session on opened hardware: the jog model (``robot.teleop``) over the same rig, guards
and detector a trial uses, and its control tick. The terminal's ``palpate teleop`` and the ROS 2
node's teleop (``palpate.ros``) both run it::

    model, rig = jog_session(stack, campaign, hw, tick=0.01)   # zeroes the sensor: it is free now
    recovered = False
    while ...:                                                   # every tick
        model.press("up")                                        # a key, a Joy's stick, ...
        obs, recovered = jog_tick(model, rig, hw.clock, recovered)
"""

from __future__ import annotations

from palpate.config.scene import CampaignConfig
from palpate.config.schema import StackConfig
from palpate.lab.hardware import Hardware
from palpate.robot.guards import Observation
from palpate.robot.indentation import State
from palpate.robot.rig import ServoFbgRig
from palpate.robot.teleop import Teleop
from palpate.robot.trial.setup import detector_for, guards_for, rig_settings
from palpate.sensor.clock import Clock


def jog_session(
    stack: StackConfig,
    campaign: CampaignConfig,
    hw: Hardware,
    tick: float,
    tube: str | None = None,
) -> tuple[Teleop, ServoFbgRig]:
    """The jog model and its rig on ``hw``, ticking every ``tick`` s, ``tube`` mounted (None:
    the first); the strains are zeroed now, so the sensor must be free, as before a trial."""
    settings = rig_settings(campaign, stack, tick)
    rig = ServoFbgRig.for_stack(hw.drive, hw.reader, stack, hw.clock, settings)
    chain = rig.zero()
    model = Teleop(
        stack.drive,
        stack.tubes,
        guards_for(campaign, stack, tick),
        detector_for(campaign, chain),
        tube_name=tube,
    )
    return model, rig


def jog_tick(
    model: Teleop, rig: ServoFbgRig, clock: Clock, recovered: bool
) -> tuple[Observation, bool]:
    """One control tick: observe, step the model, command the rig; a servo fault while
    retracting gets one reboot (``recovered``: it was tried), as in a trial."""
    obs = rig.observe(clock.now())
    cmd = model.step(obs)
    if obs.servo_fault is not None and model.state is State.RETRACTING and not recovered:
        recovered = True  # one reboot so the sensor can be pulled back, as in a trial
        rig.recover()
    rig.command(cmd)
    return obs, recovered


__all__ = ["jog_session", "jog_tick"]
